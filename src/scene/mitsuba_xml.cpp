#include "scene/mitsuba_xml.hpp"

#include <pugixml.hpp>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>

#include "errors/errors.hpp"
#include "scene/input_file.hpp"

namespace wt::mitsuba {

namespace fs = std::filesystem;

Matrix identity() {
  Matrix m{};
  m[0] = m[5] = m[10] = m[15] = 1.0;
  return m;
}

Matrix multiply(const Matrix& a, const Matrix& b) {
  Matrix c{};
  for (int r = 0; r < 4; ++r) {
    for (int k = 0; k < 4; ++k) {
      for (int col = 0; col < 4; ++col) c[4 * r + col] += a[4 * r + k] * b[4 * k + col];
    }
  }
  return c;
}

const Property* Object::find(const std::string& property) const {
  for (const Property& p : properties) {
    if (p.name == property) return &p;
  }
  return nullptr;
}

Rgb spectrum_to_rgb(const std::vector<std::pair<double, double>>& samples) {
  // The CIE 1931 2-degree colour matching functions by the multi-lobe Gaussian fit of
  // Wyman, Sloan and Shirley (JCGT 2(2), 2013), each lobe of width s1 below its mean
  // and s2 above it.
  const auto lobe = [](double l, double mean, double s1, double s2) {
    const double t = (l - mean) / (l < mean ? s1 : s2);
    return std::exp(-0.5 * t * t);
  };
  const auto cmf = [&](double l) {
    return std::array<double, 3>{
        1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) - 0.065 * lobe(l, 501.1, 20.4, 26.2),
        0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
        1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8)};
  };
  // The spectrum between its samples, linear; 0 outside them.
  const auto value = [&](double l) {
    if (l < samples.front().first || l > samples.back().first) return 0.0;
    for (size_t i = 1; i < samples.size(); ++i) {
      if (l <= samples[i].first) {
        const double t = (l - samples[i - 1].first) / (samples[i].first - samples[i - 1].first);
        return samples[i - 1].second + t * (samples[i].second - samples[i - 1].second);
      }
    }
    return samples.back().second;
  };
  // Linear sRGB of XYZ (IEC 61966-2-1's matrix).
  const auto srgb = [](const std::array<double, 3>& c) {
    return std::array<double, 3>{3.2404542 * c[0] - 1.5371385 * c[1] - 0.4985314 * c[2],
                                 -0.9692660 * c[0] + 1.8760108 * c[1] + 0.0415560 * c[2],
                                 0.0556434 * c[0] - 0.2040259 * c[1] + 1.0572252 * c[2]};
  };
  std::array<double, 3> xyz{}, white{};
  for (double l = 360.5; l < 830.0; l += 1.0) {  // 1 nm steps over 360..830 nm
    const std::array<double, 3> c = cmf(l);
    const double v = value(l);
    for (int k = 0; k < 3; ++k) {
      xyz[k] += v * c[k];
      white[k] += c[k];
    }
  }
  const std::array<double, 3> rgb = srgb(xyz), one = srgb(white);
  // Each channel over that of the constant spectrum 1, so that a flat spectrum is
  // exactly its grey.
  return {rgb[0] / one[0], rgb[1] / one[1], rgb[2] / one[2]};
}

namespace {

// The plugin objects' tags; every other element is a property, a transform's
// operation or one of default, include, ref.
const std::set<std::string>& object_tags() {
  static const std::set<std::string> tags = {"bsdf",   "shape",   "emitter", "sensor",     "texture",
                                             "film",   "sampler", "rfilter", "integrator", "medium",
                                             "phase",  "volume",  "spectrum_plugin"};
  return tags;
}

// One line of the document being read: its file and where in it the element lies.
struct Where {
  std::string file;
  int line = 0;
};

class Reader {
 public:
  explicit Reader(std::map<std::string, std::string> defines) : params_(std::move(defines)) {
    for (const auto& [name, value] : params_) given_.insert(name);
  }

  std::shared_ptr<const Object> read(const std::string& path) {
    auto scene = std::make_shared<Object>();
    scene->tag = "scene";
    scene->file = path;
    read_file(path, *scene, Where{path, 0});
    return scene;
  }

 private:
  struct Document {
    std::string path;
    std::string text;
    pugi::xml_document xml;
    // Line of a node: its offset among the newlines of the text.
    std::vector<size_t> line_starts;
    int line_of(const pugi::xml_node& node) const {
      const size_t offset = static_cast<size_t>(node.offset_debug());
      size_t lo = 0, hi = line_starts.size();
      while (lo + 1 < hi) {
        const size_t mid = (lo + hi) / 2;
        (line_starts[mid] <= offset ? lo : hi) = mid;
      }
      return static_cast<int>(lo) + 1;
    }
  };

  [[noreturn]] void fail(const Where& at, const std::string& element, const std::string& what) const {
    throw InputError(at.file + ":" + std::to_string(at.line) + ": " + element + ": " + what);
  }

  // Reads a file's <scene> children into `into` (the scene, or the object that
  // included it).
  void read_file(const std::string& path, Object& into, const Where& from) {
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(path, ec);
    const std::string key = ec ? path : canonical.string();
    for (const std::string& open : including_) {
      if (open == key) fail(from, "include", "'" + path + "' includes itself (a cycle of <include>)");
    }
    auto doc = std::make_unique<Document>();
    doc->path = path;
    doc->text = read_input_file(path, input::kScene);
    doc->line_starts.push_back(0);
    for (size_t i = 0; i < doc->text.size(); ++i) {
      if (doc->text[i] == '\n') doc->line_starts.push_back(i + 1);
    }
    const pugi::xml_parse_result parsed = doc->xml.load_buffer(doc->text.data(), doc->text.size());
    if (!parsed) {
      Where at{path, 1};
      const size_t offset = static_cast<size_t>(std::max<ptrdiff_t>(0, parsed.offset));
      for (size_t s : doc->line_starts) at.line += s != 0 && s <= offset;
      fail(at, "xml", std::string("malformed XML (") + parsed.description() + ")");
    }
    const pugi::xml_node root = doc->xml.document_element();
    if (std::string(root.name()) != "scene") {
      fail(Where{path, doc->line_of(root)}, root.name(), "the document's root must be <scene>");
    }
    // The main file's format version, as the scene's property "version" (a string).
    if (into.tag == "scene" && into.find("version") == nullptr && root.attribute("version")) {
      into.properties.push_back(Property{"version", std::string(root.attribute("version").value()), "string",
                                         doc->line_of(root)});
    }
    including_.push_back(key);
    read_children(*doc, root, into);
    including_.pop_back();
  }

  // An attribute's text with every $name replaced by its parameter's value.
  std::string attribute(const Document& doc, const pugi::xml_node& node, const char* name, bool required = true) {
    const pugi::xml_attribute a = node.attribute(name);
    const Where at{doc.path, doc.line_of(node)};
    if (!a) {
      if (required) fail(at, node.name(), std::string("attribute '") + name + "' is missing");
      return "";
    }
    std::string text = a.value(), out;
    for (size_t i = 0; i < text.size();) {
      if (text[i] != '$') {
        out += text[i++];
        continue;
      }
      size_t end = i + 1;
      while (end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_')) ++end;
      const std::string param = text.substr(i + 1, end - i - 1);
      const auto it = params_.find(param);
      if (param.empty() || it == params_.end()) {
        fail(at, node.name(), "parameter '$" + param + "' has no value (no <default> or -D gives it one)");
      }
      out += it->second;
      i = end;
    }
    return out;
  }

  // Numbers separated by commas or white space.
  std::vector<double> numbers(const Where& at, const std::string& element, const std::string& text) {
    std::vector<double> out;
    const char* p = text.c_str();
    while (*p != '\0') {
      while (*p == ',' || std::isspace(static_cast<unsigned char>(*p))) ++p;
      if (*p == '\0') break;
      char* end = nullptr;
      const double v = std::strtod(p, &end);
      if (end == p || !std::isfinite(v)) fail(at, element, "'" + text + "' is not a list of numbers");
      out.push_back(v);
      p = end;
    }
    return out;
  }

  // "wavelength:value, ..." in nanometres, the wavelengths rising, at least two.
  std::vector<std::pair<double, double>> pairs(const Where& at, const std::string& element, const std::string& text) {
    std::vector<std::pair<double, double>> out;
    size_t start = 0;
    while (start < text.size()) {
      size_t end = text.find(',', start);
      if (end == std::string::npos) end = text.size();
      std::string item = text.substr(start, end - start);
      start = end + 1;
      const size_t first = item.find_first_not_of(" \t\r\n");
      if (first == std::string::npos) continue;
      item = item.substr(first, item.find_last_not_of(" \t\r\n") - first + 1);
      const size_t colon = item.find(':');
      if (colon == std::string::npos) fail(at, element, "'" + item + "' is not a wavelength:value pair");
      const double l = number(at, element, item.substr(0, colon)), v = number(at, element, item.substr(colon + 1));
      if (!out.empty() && !(l > out.back().first)) fail(at, element, "the wavelengths must rise ('" + text + "')");
      out.emplace_back(l, v);
    }
    if (out.size() < 2) fail(at, element, "a spectrum of wavelength:value pairs needs two at least");
    return out;
  }

  double number(const Where& at, const std::string& element, const std::string& text) {
    const std::vector<double> v = numbers(at, element, text);
    if (v.size() != 1) fail(at, element, "'" + text + "' is not one number");
    return v[0];
  }

  // x, y, z: from `value` (three numbers, or one for all three where `one_for_all`), or
  // from the x, y, z attributes (each `fallback` where absent).
  Vec3 vec3(const Document& doc, const pugi::xml_node& node, double fallback, bool one_for_all) {
    const Where at{doc.path, doc.line_of(node)};
    if (node.attribute("value")) {
      const std::vector<double> v = numbers(at, node.name(), attribute(doc, node, "value"));
      if (v.size() == 1 && one_for_all) return {v[0], v[0], v[0]};
      if (v.size() != 3) fail(at, node.name(), "'value' must hold three numbers");
      return {v[0], v[1], v[2]};
    }
    Vec3 out{fallback, fallback, fallback};
    if (node.attribute("x")) out.x = number(at, node.name(), attribute(doc, node, "x"));
    if (node.attribute("y")) out.y = number(at, node.name(), attribute(doc, node, "y"));
    if (node.attribute("z")) out.z = number(at, node.name(), attribute(doc, node, "z"));
    return out;
  }

  Matrix transform(const Document& doc, const pugi::xml_node& node) {
    Matrix m = identity();
    for (const pugi::xml_node& op : node.children()) {
      if (op.type() != pugi::node_element) continue;
      const std::string name = op.name();
      const Where at{doc.path, doc.line_of(op)};
      Matrix t = identity();
      if (name == "translate") {
        const Vec3 v = vec3(doc, op, 0.0, false);
        t[3] = v.x;
        t[7] = v.y;
        t[11] = v.z;
      } else if (name == "scale") {
        const Vec3 v = vec3(doc, op, 1.0, true);
        t[0] = v.x;
        t[5] = v.y;
        t[10] = v.z;
      } else if (name == "rotate") {
        Vec3 axis = vec3(doc, op, 0.0, false);
        const double len = std::sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
        if (!(len > 0)) fail(at, name, "the axis of rotation is zero");
        axis = {axis.x / len, axis.y / len, axis.z / len};
        const double a = number(at, name, attribute(doc, op, "angle")) * (3.14159265358979323846 / 180.0);
        const double c = std::cos(a), s = std::sin(a), k = 1.0 - c;
        // Rodrigues' rotation about the unit axis, counter-clockwise for a positive angle.
        t = {c + axis.x * axis.x * k,          axis.x * axis.y * k - axis.z * s, axis.x * axis.z * k + axis.y * s, 0,
             axis.y * axis.x * k + axis.z * s, c + axis.y * axis.y * k,          axis.y * axis.z * k - axis.x * s, 0,
             axis.z * axis.x * k - axis.y * s, axis.z * axis.y * k + axis.x * s, c + axis.z * axis.z * k,          0,
             0,                                0,                                0,                                1};
      } else if (name == "matrix") {
        const std::vector<double> v = numbers(at, name, attribute(doc, op, "value"));
        if (v.size() == 9) {
          t = {v[0], v[1], v[2], 0, v[3], v[4], v[5], 0, v[6], v[7], v[8], 0, 0, 0, 0, 1};
        } else if (v.size() == 16) {
          std::copy(v.begin(), v.end(), t.begin());
        } else {
          fail(at, name, "'value' must hold 9 or 16 numbers (row by row)");
        }
      } else if (name == "lookat") {
        const std::vector<double> o = numbers(at, name, attribute(doc, op, "origin"));
        const std::vector<double> g = numbers(at, name, attribute(doc, op, "target"));
        std::vector<double> u = {0, 1, 0};
        if (op.attribute("up")) u = numbers(at, name, attribute(doc, op, "up"));
        if (o.size() != 3 || g.size() != 3 || u.size() != 3) fail(at, name, "origin, target and up are three numbers each");
        // The camera's frame as Mitsuba documents it: z toward the target, x = up x z
        // (to the left), y = z x x; the matrix maps the camera's frame to the world.
        Vec3 d{g[0] - o[0], g[1] - o[1], g[2] - o[2]};
        const double dl = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        if (!(dl > 0)) fail(at, name, "origin and target are the same point");
        d = {d.x / dl, d.y / dl, d.z / dl};
        Vec3 l{u[1] * d.z - u[2] * d.y, u[2] * d.x - u[0] * d.z, u[0] * d.y - u[1] * d.x};
        const double ll = std::sqrt(l.x * l.x + l.y * l.y + l.z * l.z);
        if (!(ll > 0)) fail(at, name, "up is parallel to the direction of view");
        l = {l.x / ll, l.y / ll, l.z / ll};
        const Vec3 up{d.y * l.z - d.z * l.y, d.z * l.x - d.x * l.z, d.x * l.y - d.y * l.x};
        t = {l.x, up.x, d.x, o[0], l.y, up.y, d.y, o[1], l.z, up.z, d.z, o[2], 0, 0, 0, 1};
      } else {
        fail(at, "transform", "unknown operation <" + name + "> (expected translate, rotate, scale, matrix or lookat)");
      }
      m = multiply(t, m);
    }
    return m;
  }

  Property property(const Document& doc, const pugi::xml_node& node) {
    const std::string kind = node.name();
    const Where at{doc.path, doc.line_of(node)};
    Property p;
    p.name = attribute(doc, node, "name");
    p.kind = kind;
    p.line = at.line;
    if (kind == "float") {
      p.value = number(at, kind, attribute(doc, node, "value"));
    } else if (kind == "integer") {
      const double v = number(at, kind, attribute(doc, node, "value"));
      if (v != std::floor(v) || std::fabs(v) > 9.0e15) fail(at, kind, "'" + attribute(doc, node, "value") + "' is not an integer");
      p.value = static_cast<int64_t>(v);
    } else if (kind == "boolean") {
      const std::string v = attribute(doc, node, "value");
      if (v != "true" && v != "false") fail(at, kind, "'" + v + "' is neither true nor false");
      p.value = v == "true";
    } else if (kind == "string") {
      p.value = attribute(doc, node, "value");
    } else if (kind == "rgb") {
      const std::vector<double> v = numbers(at, kind, attribute(doc, node, "value"));
      if (v.size() == 1) {
        p.value = Rgb{v[0], v[0], v[0]};
      } else if (v.size() == 3) {
        p.value = Rgb{v[0], v[1], v[2]};
      } else {
        fail(at, kind, "'value' must hold one number or three");
      }
    } else if (kind == "spectrum") {
      const std::string text = attribute(doc, node, "value");
      if (text.find(':') == std::string::npos) {
        const double v = number(at, kind, text);
        p.value = Rgb{v, v, v};
      } else {
        p.value = spectrum_to_rgb(pairs(at, kind, text));
      }
    } else if (kind == "point" || kind == "vector") {
      p.value = vec3(doc, node, 0.0, false);
    } else if (kind == "transform") {
      p.value = transform(doc, node);
    } else {
      fail(at, kind, "unknown element (expected a plugin object, a property, default, include or ref)");
    }
    return p;
  }

  void read_children(Document& doc, const pugi::xml_node& parent, Object& into) {
    for (const pugi::xml_node& node : parent.children()) {
      if (node.type() != pugi::node_element) continue;
      const std::string tag = node.name();
      const Where at{doc.path, doc.line_of(node)};
      if (tag == "default") {
        const std::string name = attribute(doc, node, "name");
        if (!given_.count(name)) params_[name] = attribute(doc, node, "value");
      } else if (tag == "include") {
        const std::string file = attribute(doc, node, "filename");
        const fs::path full = fs::path(file).is_absolute() ? fs::path(file) : fs::path(doc.path).parent_path() / file;
        read_file(full.lexically_normal().string(), into, at);
      } else if (tag == "ref") {
        const std::string id = attribute(doc, node, "id");
        const auto it = ids_.find(id);
        if (it == ids_.end()) fail(at, "ref", "no object has the id '" + id + "' (an id is given before it is used)");
        const std::string name = attribute(doc, node, "name", false);
        if (name.empty() || name == it->second->name) {
          into.children.push_back(it->second);
        } else {
          auto renamed = std::make_shared<Object>(*it->second);
          renamed->name = name;
          into.children.push_back(std::move(renamed));
        }
      } else if (object_tags().count(tag)) {
        auto object = std::make_shared<Object>();
        object->tag = tag;
        object->type = attribute(doc, node, "type");
        object->id = attribute(doc, node, "id", false);
        object->name = attribute(doc, node, "name", false);
        object->file = doc.path;
        object->line = at.line;
        read_children(doc, node, *object);
        if (!object->id.empty()) {
          if (ids_.count(object->id)) fail(at, tag, "the id '" + object->id + "' is given twice");
          ids_[object->id] = object;
        }
        into.children.push_back(std::move(object));
      } else {
        into.properties.push_back(property(doc, node));
      }
    }
  }

  std::map<std::string, std::string> params_;
  std::set<std::string> given_;
  std::map<std::string, std::shared_ptr<const Object>> ids_;
  std::vector<std::string> including_;
};

}  // namespace

std::shared_ptr<const Object> read_scene_xml(const std::string& path, const std::map<std::string, std::string>& defines) {
  return Reader(defines).read(path);
}

}  // namespace wt::mitsuba
