// command_errors.hpp: how every subcommand turns an exception into a message
// and an exit code, and the quiet switch (internal to puncture_app_lib).
//
// Exit codes of the `puncture` program (apps/README.md):
//   0  success
//   1  the run failed (numerical failure, FEM failure, out of memory, ...)
//   2  bad input: scene file (message names the file and the JSON path),
//      reference or scores CSV (file, line, column), a reference curve that
//      cannot be fitted or whose punctures are a guess (file and why:
//      validation::ReferenceError), command-line usage
//   3  the output cannot be written (message names the path and the OS reason)
//   128 + n  ended by signal n (130 Ctrl-C, 143 SIGTERM): staged files removed
#pragma once

#include <exception>
#include <new>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <string>

#include "puncture/apps/commands.hpp"
#include "puncture/io/csv_reader.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/reference_checks.hpp"

namespace puncture::apps {

/// A bad command-line value (exit code 2).
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A bad input file other than the scene (exit code 2); the message names it.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Runs `body` (returns the exit code) and maps exceptions to exit codes (see
/// above). Messages that do not name their own context are prefixed by
/// `context` (e.g. the scene file) when not empty.
template <class Body>
int report_errors(std::ostream& err, const std::string& context, Body&& body) {
  const std::string prefix = context.empty() ? std::string() : context + ": ";
  try {
    return body();
  } catch (const SceneError& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const validation::CurveFormatError& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const io::CsvFormatError& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const validation::ReferenceError& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const InputError& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const UsageError& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const io::OutputError& e) {
    err << "error: " << e.what() << '\n';
    return kExitOutput;
  } catch (const std::bad_alloc&) {
    err << "error: " << prefix << "out of memory\n";
    return kExitFailure;
  } catch (const std::exception& e) {
    err << "error: " << prefix << e.what() << '\n';
    return kExitFailure;
  }
}

/// A stream that discards everything (what `-q` prints to).
class NullStream : public std::ostream {
 public:
  NullStream() : std::ostream(&buffer_) {}

 private:
  struct Discard : std::streambuf {
    int overflow(int c) override { return c; }
    std::streamsize xsputn(const char*, std::streamsize n) override { return n; }
  } buffer_;
};

}  // namespace puncture::apps
