"""Self-test of scripts/check_readme_figures.py: a README and a results page in a temporary
folder; a wrong figure must be reported (file, line, figure, page), a right one must pass.

Runs under pytest (python3 -m pytest -q tests/scripts/test_check_readme_figures.py) and on its
own without pytest (python3 tests/scripts/test_check_readme_figures.py), which is how ctest
runs it (test docs.readme_figures_selftest in tests/CMakeLists.txt).
"""
import importlib.util
import io
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("check_readme_figures", ROOT / "scripts" / "check_readme_figures.py")
crf = importlib.util.module_from_spec(_spec)
sys.modules["check_readme_figures"] = crf   # dataclasses look their module up by name
_spec.loader.exec_module(crf)


def make(tmp_path, readme, pages):
    """Write README.md and results/<path> pages under tmp_path; run the check; (rc, output)."""
    for rel, text in pages.items():
        p = tmp_path / "results" / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text, encoding="utf-8")
    (tmp_path / "README.md").write_text(readme, encoding="utf-8")
    out = io.StringIO()
    rc = crf.run([str(tmp_path / "README.md")], str(tmp_path), out=out)
    return rc, out.getvalue()


PAGE = "# Study\n\nMade by `run.sh` on vm, 2026-12-04T17:55:00Z.\n\nThe skin punctures at 2.94 N after 9.4 mm; 8 of 12 accepted.\n"


def test_correct_figures_pass(tmp_path):
    rc, out = make(tmp_path, "# T\n\nThe FEM punctures skin at 2.94 N after 9.4 mm, 8 of 12 accepted "
                             "([study](results/study/README.md)).\n", {"study/README.md": PAGE})
    assert rc == 0, out
    assert "3 figures" in out


def test_wrong_figure_is_reported_with_line_and_page(tmp_path):
    readme = "# T\n\nIntro without figures.\n\nThe FEM punctures skin at 2.53 N after 9.4 mm\n(+27 %, [study](results/study/README.md)).\n"
    rc, out = make(tmp_path, readme, {"study/README.md": PAGE})
    assert rc == 1
    assert "README.md:5: figure '2.53 N' not found on results/study/README.md" in out
    assert "README.md:6: figure '27 %' not found" in out
    assert "'9.4 mm'" not in out


def test_a_number_is_not_found_inside_a_longer_one(tmp_path):
    rc, out = make(tmp_path, "Calibrated in 8.5 s ([c](results/cal.md)).\n",
                   {"cal.md": "761 model runs in 8.512 s (wall), 2026-12-04T17:54:59Z.\n"})
    assert rc == 1 and "'8.5 s'" in out
    rc, out = make(tmp_path, "Calibrated in 12 s ([c](results/cal.md)).\n",
                   {"cal.md": "761 model runs in 8.512 s (wall), 2026-12-04T17:54:59Z.\n"})
    assert rc == 1 and "'12 s'" in out, "the page's date must not supply the 12"


def test_minus_thousands_and_sign(tmp_path):
    page = {"p.md": "withdrawal min -0.892 N; 1000 s; rise 0.5 N\n"}
    rc, out = make(tmp_path, "Pulls back at \u22120.892 N after 1,000 s ([p](results/p.md)).\n", page)
    assert rc == 0, out
    rc, out = make(tmp_path, "It falls by -0.5 N ([p](results/p.md)).\n", page)
    assert rc == 1 and "'-0.5 N'" in out


def test_count_is_checked_as_a_phrase(tmp_path):
    rc, out = make(tmp_path, "Held out: 7 of 12 ([h](results/study/README.md)).\n", {"study/README.md": PAGE})
    assert rc == 1 and "'7 of 12'" in out


def test_ignored_numbers_and_allowlist(tmp_path):
    readme = ("Made 2026-12-04 17:55 UTC, program 0.1.0, git 6554da2, `--depth 3.5`, Eq. 5, Sec. 3.3, "
              "10 mm/s and a 1 kHz loop ([v2.5 page](results/v2.5/README.md)): 2.94 N.\n")
    rc, out = make(tmp_path, readme, {"v2.5/README.md": PAGE})
    assert rc == 0, out
    assert "1 figures" in out and "2 allowlisted" in out


def test_figure_without_a_results_page_is_reported(tmp_path):
    rc, out = make(tmp_path, "# T\n\nThe default reference punctured the muscle 2.7 % higher.\n", {"study/README.md": PAGE})
    assert rc == 1 and "README.md:3: figure '2.7 %' quotes no results page" in out


def test_table_takes_the_link_of_its_introduction_and_folder_links(tmp_path):
    readme = ("The in-sample numbers ([report](results/study/)):\n\n"
              "| layer | force |\n|---|---|\n| skin | 2.94 N |\n| fat | 3.01 N |\n")
    rc, out = make(tmp_path, readme, {"study/README.md": PAGE})
    assert rc == 1
    assert "README.md:6: figure '3.01 N' not found on results/study/README.md (linked from the table's introduction)" in out
    assert "'2.94 N'" not in out


def test_sentence_link_wins_over_the_paragraph(tmp_path):
    readme = "Skin at 2.94 N ([a](results/a.md)). Fat at 2.48 N ([b](results/b.md)).\n"
    rc, out = make(tmp_path, readme, {"a.md": "2.94 N\n", "b.md": "2.94 N\n"})
    assert rc == 1 and "'2.48 N' not found on results/b.md" in out and "'2.94 N'" not in out


def test_marker_names_the_page(tmp_path):
    readme = "<!-- figures: results/a.md -->\nThe peak is 2.94 N.\n"
    rc, out = make(tmp_path, readme, {"a.md": "peak 2.94 N\n"})
    assert rc == 0, out


def test_missing_target_and_ambiguous_folder(tmp_path):
    rc, out = make(tmp_path, "See [gone](results/gone/README.md).\n", {"a.md": "x\n"})
    assert rc == 1 and "results/gone/README.md does not exist" in out
    pages = {"two/a.md": "1.5 N\n", "two/b.md": "1.5 N\n", "two/plot.png": ""}
    rc, out = make(tmp_path, "The plot ([p](results/two/plot.png)) peaks at 1.5 N.\n", pages)
    assert rc == 1 and "names no single page" in out
    rc, out = make(tmp_path, "The plot: [p](results/two/plot.png).\n", pages)
    assert rc == 0, out


def test_code_blocks_are_skipped(tmp_path):
    readme = "```bash\nrun --speed 3.5  # 9.9 N\n```\n\n    indented 7.7 N\n"
    rc, out = make(tmp_path, readme, {"a.md": "x\n"})
    assert rc == 0 and "0 figures" in out, out


def test_the_repository_readmes_pass():
    out = io.StringIO()
    rc = crf.run([str(ROOT / "README.md"), str(ROOT / "results" / "README.md")], str(ROOT), out=out)
    assert rc == 0, out.getvalue()


if __name__ == "__main__":
    import selftest  # tests/scripts/, beside this file
    sys.exit(selftest.run(globals()))
