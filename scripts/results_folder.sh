# results_folder.sh (sourced by the results scripts): write a results folder so
# that a failed or interrupted run leaves the committed one as it was.
#   replace_results_folder OUT CMD [ARGS...]
# moves OUT aside to OUT.previous, runs CMD (which writes OUT), then drops
# OUT.previous; when CMD fails, or on INT/TERM/HUP, puts OUT.previous back and
# says so on stderr (returns CMD's status; 130 when interrupted).
replace_results_folder() {
  local out="$1"; shift
  rm -rf "$out.previous"
  [ -d "$out" ] && mv "$out" "$out.previous"
  # shellcheck disable=SC2064  # $out is expanded now, on purpose
  trap "rm -rf '$out'; [ -d '$out.previous' ] && mv '$out.previous' '$out'; echo '$out: interrupted; left as it was' >&2; exit 130" INT TERM HUP
  local status=0
  "$@" || status=$?
  trap - INT TERM HUP
  if [ "$status" -ne 0 ]; then
    rm -rf "$out"
    [ -d "$out.previous" ] && mv "$out.previous" "$out"
    echo "$out: $1 failed (exit $status); left as it was" >&2
    return "$status"
  fi
  rm -rf "$out.previous"
}
