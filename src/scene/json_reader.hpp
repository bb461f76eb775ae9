// Reading JSON input files (scenes, jobs files, bench specs) strictly: a repeated
// key or an unknown one is an error, and every error is one line naming the file
// and the JSON pointer of the offending field.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "scene/input_file.hpp"
#include "scene/scene.hpp"

namespace wt {

using json = nlohmann::json;

// A JSON pointer built on the stack as the reader descends, turned into text only
// for a message. A child refers to its parent: use `path / "key"` and `path / i` as
// arguments, never keep one beyond the statement that made its parent.
class JsonPath {
 public:
  JsonPath() = default;  // the document's root
  JsonPath operator/(std::string_view key) const { return JsonPath(this, key, 0); }
  JsonPath operator/(size_t index) const { return JsonPath(this, {}, index + 1); }
  std::string str() const;  // "/a/0/b"; "/" for the root

 private:
  JsonPath(const JsonPath* parent, std::string_view key, size_t index_plus_one)
      : parent_(parent), key_(key), index_plus_one_(index_plus_one) {}
  void append(std::string& out) const;

  const JsonPath* parent_ = nullptr;
  std::string_view key_;
  size_t index_plus_one_ = 0;  // 0: an object's member (or the root)
};

// Parses JSON text, rejecting a key repeated in one object (nlohmann would keep the
// last value without a word). Time and memory are linear in the text. Throws
// InputError "<source>: malformed JSON: ..." or "<source>: /path: duplicate key".
// With `duplicates`, a repeated key is not thrown but its JSON pointer recorded there,
// the first value kept (a jobs file fails the one job that holds it).
json parse_json(const std::string& text, const std::string& source, std::vector<std::string>* duplicates = nullptr);

// Reads a whole input file (read_input_file: a regular file within its kind's limit)
// and parses it as above.
json read_json_file(const std::string& path, const InputKind& kind);

// The typed field readers: each checks one value and throws InputError
// "<source>: <path>: <what is wrong>".
class JsonReader {
 public:
  explicit JsonReader(std::string source) : source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  [[noreturn]] void fail_at(const JsonPath& path, const std::string& what) const;

  void object(const json& j, const JsonPath& path) const;
  // Fails on a key not in `allowed`; `type`: the object's type where the allowed
  // keys depend on it.
  void check_keys(const json& obj, const JsonPath& path, const std::vector<std::string>& allowed,
                  const std::string& type = "") const;
  const json& required(const json& obj, const JsonPath& path, const char* key) const;
  const json& array(const json& j, const JsonPath& path) const;
  const std::string& string(const json& j, const JsonPath& path) const;
  bool boolean(const json& j, const JsonPath& path) const;
  // A string that must be one of `choices`; returns its index.
  size_t choice(const json& j, const JsonPath& path, const std::vector<std::string>& choices) const;
  // Any finite number within float range (every scene number ends up in a float).
  float number(const json& j, const JsonPath& path) const;
  float positive(const json& j, const JsonPath& path) const;
  float non_negative(const json& j, const JsonPath& path) const;
  float unit_interval(const json& j, const JsonPath& path) const;
  // A finite double in [lo, hi].
  double real(const json& j, const JsonPath& path, double lo, double hi) const;
  // An integer in lo..hi; integral floats (2.0, 1e3) count as integers.
  int64_t integer(const json& j, const JsonPath& path, int64_t lo, int64_t hi) const;
  // A setting of the table (render/settings.hpp) within its range: an integer one's
  // as integer() reads it, a real one's (the noise threshold) in (real_above, real_most].
  int64_t integer_setting(const json& j, const JsonPath& path, SettingId id) const;
  double real_setting(const json& j, const JsonPath& path, SettingId id) const;

 private:
  std::string source_;
};


}  // namespace wt
