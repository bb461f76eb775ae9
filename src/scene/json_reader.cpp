#include "errors/errors.hpp"
#include "scene/json_reader.hpp"

#include <algorithm>
#include <deque>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <utility>

namespace wt {

namespace {

void append_token(std::string& out, std::string_view key) {
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
}

// Builds the document from nlohmann's SAX events, as nlohmann's own DOM parser
// does, and stops at a key repeated in one object. Each event costs O(1) (an
// object's key costs one map insertion). nlohmann's parse-with-callback route
// rescans the parent array every time an object closes: quadratic in a long
// array of objects, such as a scene's spheres.
class DomBuilder : public nlohmann::json_sax<json> {
 public:
  DomBuilder(const std::string& source, std::vector<std::string>* duplicates)
      : source_(source), duplicates_(duplicates) {}

  json take() { return std::move(root_); }

  bool null() override { return add(nullptr); }
  bool boolean(bool v) override { return add(v); }
  bool number_integer(number_integer_t v) override { return add(v); }
  bool number_unsigned(number_unsigned_t v) override { return add(v); }
  bool number_float(number_float_t v, const string_t&) override { return add(v); }
  bool string(string_t& v) override { return add(std::move(v)); }
  bool binary(binary_t& v) override { return add(std::move(v)); }

  bool start_object(std::size_t) override {
    stack_.push_back(add_container(json::object()));
    return true;
  }
  bool key(string_t& k) override {
    // try_emplace leaves k alone when the key is there already.
    auto [it, inserted] = stack_.back()->get_ref<json::object_t&>().try_emplace(std::move(k));
    if (!inserted) {
      std::string path = path_of_open_containers();
      path += '/';
      append_token(path, k);  // not moved from: try_emplace inserted nothing
      if (!duplicates_) throw InputError(source_ + ": " + path + ": duplicate key");
      // Recorded, and the repeated value read into a place of its own and dropped.
      duplicates_->push_back(std::move(path));
      member_ = &dropped_.emplace_back();
      return true;
    }
    member_ = &it->second;
    return true;
  }
  bool end_object() override {
    stack_.pop_back();
    return true;
  }
  bool start_array(std::size_t) override {
    stack_.push_back(add_container(json::array()));
    return true;
  }
  bool end_array() override {
    stack_.pop_back();
    return true;
  }

  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override {
    // Drop nlohmann's "[json.exception.parse_error.101] " tag; the rest says what and
    // where (line and column) in words.
    std::string what = e.what();
    size_t tag_end = what.find("] ");
    if (what.rfind("[json.exception.", 0) == 0 && tag_end != std::string::npos) what = what.substr(tag_end + 2);
    throw InputError(source_ + ": malformed JSON: " + what);
  }

 private:
  template <class V>
  json* place(V&& v) {
    if (stack_.empty()) {
      root_ = json(std::forward<V>(v));
      return &root_;
    }
    json& top = *stack_.back();
    if (top.is_array()) {
      json::array_t& a = top.get_ref<json::array_t&>();
      a.emplace_back(std::forward<V>(v));
      return &a.back();
    }
    *member_ = json(std::forward<V>(v));
    return member_;
  }
  template <class V>
  bool add(V&& v) {
    place(std::forward<V>(v));
    return true;
  }
  json* add_container(json&& empty) { return place(std::move(empty)); }

  // The open containers' path: in an array the element being read is the last one,
  // in an object it is the member whose key came last.
  std::string path_of_open_containers() const {
    std::string out;
    for (size_t i = 0; i + 1 < stack_.size(); ++i) {
      const json& c = *stack_[i];
      out += '/';
      if (c.is_array()) {
        out += std::to_string(c.size() - 1);
      } else {
        for (auto it = c.begin(); it != c.end(); ++it) {
          if (&it.value() == stack_[i + 1]) append_token(out, it.key());
        }
      }
    }
    return out;
  }

  const std::string& source_;
  std::vector<std::string>* duplicates_;
  std::deque<json> dropped_;  // the values of repeated keys (a deque: their addresses stay put)
  json root_;
  std::vector<json*> stack_;  // the open containers, outermost first
  json* member_ = nullptr;    // where the next value of the innermost object goes
};

}  // namespace

std::string JsonPath::str() const {
  std::string out;
  append(out);
  return out.empty() ? "/" : out;
}

void JsonPath::append(std::string& out) const {
  if (!parent_) return;
  parent_->append(out);
  out += '/';
  if (index_plus_one_ > 0) {
    out += std::to_string(index_plus_one_ - 1);
  } else {
    append_token(out, key_);
  }
}

json parse_json(const std::string& text, const std::string& source, std::vector<std::string>* duplicates) {
  DomBuilder builder(source, duplicates);
  json::sax_parse(text, &builder);
  return builder.take();
}

json read_json_file(const std::string& path, const InputKind& kind) {
  return parse_json(read_input_file(path, kind), path);
}

void JsonReader::fail_at(const JsonPath& path, const std::string& what) const {
  throw InputError(source_ + ": " + path.str() + ": " + what);
}

void JsonReader::object(const json& j, const JsonPath& path) const {
  if (!j.is_object()) fail_at(path, std::string("must be an object (got ") + j.type_name() + ")");
}

void JsonReader::check_keys(const json& obj, const JsonPath& path, const std::vector<std::string>& allowed,
                            const std::string& type) const {
  object(obj, path);
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end()) {
      fail_at(path / it.key(), "unknown key" + (type.empty() ? "" : " for type '" + type + "'") + " (expected " +
                                   listed(allowed) + ")");
    }
  }
}

const json& JsonReader::required(const json& obj, const JsonPath& path, const char* key) const {
  auto it = obj.find(key);
  if (it == obj.end()) fail_at(path / key, "required key is missing");
  return *it;
}

const json& JsonReader::array(const json& j, const JsonPath& path) const {
  if (!j.is_array()) fail_at(path, std::string("must be an array (got ") + j.type_name() + ")");
  return j;
}

const std::string& JsonReader::string(const json& j, const JsonPath& path) const {
  if (!j.is_string()) fail_at(path, std::string("must be a string (got ") + j.type_name() + ")");
  return j.get_ref<const std::string&>();
}

bool JsonReader::boolean(const json& j, const JsonPath& path) const {
  if (!j.is_boolean()) fail_at(path, std::string("must be true or false (got ") + j.type_name() + ")");
  return j.get<bool>();
}

size_t JsonReader::choice(const json& j, const JsonPath& path, const std::vector<std::string>& choices) const {
  const std::string& s = string(j, path);
  for (size_t i = 0; i < choices.size(); ++i) {
    if (choices[i] == s) return i;
  }
  fail_at(path, "unknown value '" + s + "' (expected " + listed(choices) + ")");
}

float JsonReader::number(const json& j, const JsonPath& path) const {
  if (!j.is_number()) fail_at(path, std::string("must be a number (got ") + j.type_name() + ")");
  double v = j.get<double>();
  if (!(std::fabs(v) <= FLT_MAX)) fail_at(path, "must be a finite number within float range (got " + j.dump() + ")");
  return static_cast<float>(v);
}

float JsonReader::positive(const json& j, const JsonPath& path) const {
  float v = number(j, path);
  if (!(v > 0.0f)) fail_at(path, "must be > 0 (got " + j.dump() + ")");
  return v;
}

float JsonReader::non_negative(const json& j, const JsonPath& path) const {
  float v = number(j, path);
  if (!(v >= 0.0f)) fail_at(path, "must be >= 0 (got " + j.dump() + ")");
  return v;
}

float JsonReader::unit_interval(const json& j, const JsonPath& path) const {
  float v = number(j, path);
  if (!(v >= 0.0f && v <= 1.0f)) fail_at(path, "must be in [0, 1] (got " + j.dump() + ")");
  return v;
}

double JsonReader::real(const json& j, const JsonPath& path, double lo, double hi) const {
  if (!j.is_number()) fail_at(path, std::string("must be a number (got ") + j.type_name() + ")");
  double v = j.get<double>();
  if (!(v >= lo && v <= hi)) {
    fail_at(path, "must be a number in [" + json(lo).dump() + ", " + json(hi).dump() + "] (got " + j.dump() + ")");
  }
  return v;
}

int64_t JsonReader::integer_setting(const json& j, const JsonPath& path, SettingId id) const {
  const Setting& s = setting(id);
  return integer(j, path, s.lo, s.hi);
}

double JsonReader::real_setting(const json& j, const JsonPath& path, SettingId id) const {
  const Setting& s = setting(id);
  if (!j.is_number()) fail_at(path, std::string("must be a number (got ") + j.type_name() + ")");
  const double v = j.get<double>();
  try {
    check_real_setting(id, v);
  } catch (const InputError& e) {
    // "<key>: must be ...", said of the field instead.
    fail_at(path, std::string(e.what()).substr(std::strlen(s.key) + 2));
  }
  return v;
}

int64_t JsonReader::integer(const json& j, const JsonPath& path, int64_t lo, int64_t hi) const {
  auto range = [&] { return "must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi); };
  if (!j.is_number()) fail_at(path, range() + " (got " + j.type_name() + ")");
  bool representable = true;
  int64_t v = 0;
  if (j.is_number_unsigned()) {
    representable = j.get<uint64_t>() <= static_cast<uint64_t>(INT64_MAX);
    v = representable ? j.get<int64_t>() : 0;
  } else if (j.is_number_integer()) {
    v = j.get<int64_t>();
  } else {
    // 1e3 and 2.0 are integers written as floats; accept them.
    double d = j.get<double>();
    representable = std::floor(d) == d && d >= static_cast<double>(lo) && d <= static_cast<double>(hi);
    v = representable ? static_cast<int64_t>(d) : 0;
  }
  if (!representable || v < lo || v > hi) fail_at(path, range() + " (got " + j.dump() + ")");
  return v;
}

}  // namespace wt
