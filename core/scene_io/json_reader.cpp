// json_reader.cpp: see json_reader.hpp.
#include "json_reader.hpp"

#include <vector>

#include "puncture/scene_io.hpp"

namespace puncture::detail {

using json = nlohmann::json;

std::string json_pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

namespace {

class PathTrackingBuilder : public nlohmann::json_sax<json> {
 public:
  explicit PathTrackingBuilder(json& root) : root_(root) {}

  bool null() override { return add(json(nullptr)); }
  bool boolean(bool v) override { return add(json(v)); }
  bool number_integer(number_integer_t v) override { return add(json(v)); }
  bool number_unsigned(number_unsigned_t v) override { return add(json(v)); }
  bool number_float(number_float_t v, const string_t&) override { return add(json(v)); }
  bool string(string_t& v) override { return add(json(v)); }
  bool binary(binary_t& v) override { return add(json::binary(v)); }

  bool start_object(std::size_t) override { return open(json::object(), false); }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(json::array(), true); }
  bool end_array() override { return close(); }

  bool key(string_t& k) override {
    Frame& f = frames_.back();
    if (f.container->contains(k)) {
      error_path_ = path(/*include_last_key=*/false) + "/" + json_pointer_token(k);
      error_ = "duplicate key '" + k + "' (a key may appear only once in an object)";
      return false;
    }
    f.key = k;
    f.has_key = true;
    return true;
  }

  bool parse_error(std::size_t, const std::string& token, const nlohmann::detail::exception& ex) override {
    error_path_ = path();
    if (ex.id == 406) {
      error_ = "number out of range: '" + token + "' (a double holds at most about 1.8e308)";
    } else {
      std::string what = ex.what();
      const auto pos = what.find("parse error");
      error_ = "malformed JSON: " + (pos == std::string::npos ? what : what.substr(pos));
    }
    return false;
  }

  const std::string& error() const { return error_; }
  const std::string& error_path() const { return error_path_; }

 private:
  struct Frame {
    json* container;
    bool is_array;
    std::string key;
    bool has_key = false;
    std::size_t count = 0;  ///< completed elements (arrays): the index of the one being read
  };

  /// Path of the value being read; without the innermost object's key when
  /// include_last_key is false (the path of that object).
  std::string path(bool include_last_key = true) const {
    std::string p;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      const Frame& f = frames_[i];
      const bool last = i + 1 == frames_.size();
      if (f.is_array)
        p += "/" + std::to_string(f.count);
      else if (f.has_key && (include_last_key || !last))
        p += "/" + json_pointer_token(f.key);
    }
    return p;
  }

  json* add_value(json&& v) {
    if (frames_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    Frame& f = frames_.back();
    if (f.is_array) {
      f.container->push_back(std::move(v));
      return &f.container->back();
    }
    json& slot = (*f.container)[f.key];
    slot = std::move(v);
    return &slot;
  }

  bool add(json&& v) {
    add_value(std::move(v));
    if (!frames_.empty() && frames_.back().is_array) ++frames_.back().count;
    return true;
  }

  bool open(json&& v, bool is_array) {
    if (static_cast<int>(frames_.size()) >= kMaxJsonDepth) {
      error_path_ = path();
      error_ = "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
      return false;
    }
    json* c = add_value(std::move(v));
    frames_.push_back({c, is_array, {}, false, 0});
    return true;
  }

  bool close() {
    frames_.pop_back();
    if (!frames_.empty() && frames_.back().is_array) ++frames_.back().count;
    return true;
  }

  json& root_;
  std::vector<Frame> frames_;
  std::string error_, error_path_;
};

}  // namespace

json parse_json_with_paths(const std::string& text, const std::string& file) {
  json root;
  PathTrackingBuilder builder(root);
  const bool ok = json::sax_parse(text, &builder, json::input_format_t::json, /*strict=*/true);
  if (!ok) throw SceneError(file, builder.error_path(), builder.error().empty() ? "malformed JSON" : builder.error());
  return root;
}

}  // namespace puncture::detail
