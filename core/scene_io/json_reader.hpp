// json_reader.hpp (internal to puncture_scene_io): JSON text -> nlohmann::json
// with errors that name the JSON path.
//
// Built on nlohmann's SAX parser, tracking the path of the value being read:
//   * malformed JSON and numbers out of the double range (1e309) are reported
//     as SceneError(file, <path where it happened>, ...);
//   * a key that appears twice in one object is rejected (SceneError at the
//     path of the second occurrence): nlohmann's DOM parser would keep the
//     last one silently;
//   * nesting deeper than kMaxJsonDepth is rejected;
//   * a UTF-8 byte-order mark at the start is accepted and ignored (nlohmann
//     skips it; editors on some systems write one); one anywhere else, and
//     other encodings (UTF-16), are malformed JSON.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace puncture::detail {

constexpr int kMaxJsonDepth = 64;

/// JSON pointer escaping of one key (RFC 6901: '~' -> "~0", '/' -> "~1").
std::string json_pointer_token(const std::string& key);

nlohmann::json parse_json_with_paths(const std::string& text, const std::string& file);

}  // namespace puncture::detail
