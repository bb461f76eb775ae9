#include "scene/mitsuba_scene.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "errors/errors.hpp"
#include "scene/bsdf_tables.hpp"
#include "scene/input_file.hpp"
#include "scene/mitsuba_metals.hpp"
#include "wavetrace/bsdfs/microfacet.hpp"

namespace wt::mitsuba {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegrees = 180.0 / kPi;

std::string where(const Object& o, int line = 0) {
  return o.file + ":" + std::to_string(line > 0 ? line : o.line) + ": " + (o.type.empty() ? o.tag : o.type);
}

[[noreturn]] void fail(const Object& o, const std::string& what, int line = 0) {
  throw InputError(where(o, line) + ": " + what);
}

json triple(double x, double y, double z) { return json::array({x, y, z}); }
json triple(const Rgb& c) { return triple(c.r, c.g, c.b); }
json triple(const Vec3& v) { return triple(v.x, v.y, v.z); }

Vec3 point_of(const Matrix& m, const Vec3& p) {
  return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
          m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}
Vec3 vector_of(const Matrix& m, const Vec3& v) {
  return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
          m[8] * v.x + m[9] * v.y + m[10] * v.z};
}
double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double length(const Vec3& v) { return std::sqrt(dot(v, v)); }
Vec3 scaled(const Vec3& v, double s) { return {v.x * s, v.y * s, v.z * s}; }

bool is_identity(const Matrix& m) { return m == identity(); }

// A property's value as a double (a float or an integer property).
std::optional<double> as_number(const Property& p) {
  if (const double* d = std::get_if<double>(&p.value)) return *d;
  if (const int64_t* i = std::get_if<int64_t>(&p.value)) return static_cast<double>(*i);
  return std::nullopt;
}

// Mitsuba's named indices of refraction (its documentation's table of measured
// values at 589.3 nm, as tabulated in standard references).
const std::map<std::string, double>& named_iors() {
  static const std::map<std::string, double> iors = {
      {"vacuum", 1.0},          {"helium", 1.000036},     {"hydrogen", 1.000132},  {"air", 1.000277},
      {"carbon dioxide", 1.00045}, {"water", 1.3330},     {"acetone", 1.36},       {"ethanol", 1.361},
      {"carbon tetrachloride", 1.461}, {"glycerol", 1.4729}, {"benzene", 1.501},   {"silicone oil", 1.52045},
      {"bromine", 1.661},       {"water ice", 1.31},      {"fused quartz", 1.458}, {"pyrex", 1.470},
      {"acrylic glass", 1.49},  {"polypropylene", 1.49},  {"bk7", 1.5046},         {"sodium chloride", 1.544},
      {"amber", 1.55},          {"pet", 1.5750},          {"diamond", 2.419}};
  return iors;
}

// Mitsuba's conductor presets that wavetrace holds measured data for (its own
// presets, src/scene/conductor_presets.hpp): the metal's chemical symbol.
const std::map<std::string, std::string>& named_metals() {
  static const std::map<std::string, std::string> metals = {
      {"Au", "gold"}, {"Ag", "silver"}, {"Cu", "copper"}, {"Al", "aluminium"}, {"Cr", "chromium"}, {"Ni_palik", "nickel"}};
  return metals;
}

// Mitsuba's other named conductors: the RGB eta and k its RGB variants load for
// them (scene/mitsuba_metals.hpp, written by tools/mitsuba_metals.py), or null.
const MitsubaMetal* mitsuba_metal(const std::string& name) {
  for (const MitsubaMetal& metal : kMitsubaMetals) {
    if (name == metal.name) return &metal;
  }
  return nullptr;
}

// A plugin's properties and nested objects as the mapping reads them: whatever is
// left unread at the end is a parameter wavetrace does not support.
class Plugin {
 public:
  explicit Plugin(const Object& o) : o_(o), used_(o.properties.size(), false), taken_(o.children.size(), false) {}

  const Object& object() const { return o_; }
  [[noreturn]] void fail(const std::string& what, int line = 0) const { mitsuba::fail(o_, what, line); }

  const Property* take(const std::string& name) {
    for (size_t i = 0; i < o_.properties.size(); ++i) {
      if (o_.properties[i].name == name) {
        used_[i] = true;
        return &o_.properties[i];
      }
    }
    return nullptr;
  }
  bool has(const std::string& name) const { return o_.find(name) != nullptr || named_child(name) != nullptr; }
  // Read and not applied (what does not change the converged image).
  void ignore(const std::string& name) {
    take(name);
    if (const Object* c = named_child(name)) taken_[index_of(c)] = true;
  }

  double number(const std::string& name, double fallback) {
    const Property* p = take(name);
    if (p == nullptr) return fallback;
    const std::optional<double> v = as_number(*p);
    if (!v) fail("'" + name + "' must be a float or an integer (got <" + p->kind + ">)", p->line);
    return *v;
  }
  bool boolean(const std::string& name, bool fallback) {
    const Property* p = take(name);
    if (p == nullptr) return fallback;
    const bool* b = std::get_if<bool>(&p->value);
    if (b == nullptr) fail("'" + name + "' must be a <boolean> (got <" + p->kind + ">)", p->line);
    return *b;
  }
  std::string string(const std::string& name, const std::string& fallback) {
    const Property* p = take(name);
    if (p == nullptr) return fallback;
    const std::string* s = std::get_if<std::string>(&p->value);
    if (s == nullptr) fail("'" + name + "' must be a <string> (got <" + p->kind + ">)", p->line);
    return *s;
  }
  Vec3 point(const std::string& name, const Vec3& fallback) {
    const Property* p = take(name);
    if (p == nullptr) return fallback;
    const Vec3* v = std::get_if<Vec3>(&p->value);
    if (v == nullptr) fail("'" + name + "' must be a <point> or <vector> (got <" + p->kind + ">)", p->line);
    return *v;
  }
  Matrix transform(const std::string& name) {
    const Property* p = take(name);
    if (p == nullptr) return identity();
    const Matrix* m = std::get_if<Matrix>(&p->value);
    if (m == nullptr) fail("'" + name + "' must be a <transform> (got <" + p->kind + ">)", p->line);
    return *m;
  }
  // A colour: <rgb>, <spectrum> or a number (a grey).
  std::optional<Rgb> colour(const std::string& name) {
    const Property* p = take(name);
    if (p == nullptr) return std::nullopt;
    if (const Rgb* c = std::get_if<Rgb>(&p->value)) return *c;
    if (const std::optional<double> v = as_number(*p)) return Rgb{*v, *v, *v};
    fail("'" + name + "' must be a colour (<rgb>, <spectrum> or a number; got <" + p->kind + ">)", p->line);
  }
  Rgb colour(const std::string& name, const Rgb& fallback) { return colour(name).value_or(fallback); }
  // The nested object of `tag` named `name`; with an empty name, the next unnamed
  // one not yet taken, or any not taken where `any_name`.
  const Object* child(const std::string& tag, const std::string& name = "", bool any_name = false) {
    for (size_t i = 0; i < o_.children.size(); ++i) {
      const Object& c = *o_.children[i];
      if (taken_[i] || c.tag != tag) continue;
      if (c.name == name || (name.empty() && any_name)) {
        taken_[i] = true;
        return &c;
      }
    }
    return nullptr;
  }
  // A parameter given as a property or as a nested object (a texture) of that name.
  bool nested(const std::string& name) const { return named_child(name) != nullptr; }

  // Every property and nested object read: the first one that is not is an error.
  void finish() const {
    for (size_t i = 0; i < used_.size(); ++i) {
      if (!used_[i]) fail("parameter '" + o_.properties[i].name + "' is not supported", o_.properties[i].line);
    }
    for (size_t i = 0; i < taken_.size(); ++i) {
      if (taken_[i]) continue;
      const Object& c = *o_.children[i];
      const std::string what = "<" + c.tag + " type=\"" + c.type + "\"" + (c.name.empty() ? "" : " name=\"" + c.name + "\"") + ">";
      fail("a nested " + what + " is not supported here", c.line);
    }
  }

 private:
  const Object* named_child(const std::string& name) const {
    for (const auto& c : o_.children) {
      if (c->name == name) return c.get();
    }
    return nullptr;
  }
  size_t index_of(const Object* c) const {
    for (size_t i = 0; i < o_.children.size(); ++i) {
      if (o_.children[i].get() == c) return i;
    }
    return 0;
  }

  const Object& o_;
  std::vector<bool> used_;
  std::vector<bool> taken_;
};

// What a BSDF makes of a surface: its material, and the alpha of a `mask`.
struct Surface {
  json material;
  json alpha;  // null: opaque
};

class Converter {
 public:
  explicit Converter(const Object& scene) : scene_(scene), base_(fs::path(scene.file).parent_path()) {}

  json run() {
    Plugin p(scene_);
    // Mitsuba 0.x's files name their parameters otherwise (maxDepth, intIOR): Mitsuba 3
    // reads them by upgrading them first, which wavetrace does not.
    const std::string version = p.string("version", "3.0.0");
    if (std::atoi(version.c_str()) < 2) {
      p.fail("version " + version + ": a Mitsuba 0.x scene, whose parameter names wavetrace does not read (give "
             "a Mitsuba 3 scene, version=\"3.0.0\")",
             scene_.find("version")->line);
    }
    const Object* sensor = p.child("sensor", "", true);
    if (sensor == nullptr) p.fail("the scene has no <sensor> (wavetrace needs its camera)");
    if (const Object* other = p.child("sensor", "", true)) fail(*other, "a second sensor is not supported (one camera a scene)");
    read_sensor(*sensor);
    const Object* integrator = p.child("integrator", "", true);
    read_integrator(integrator);
    if (const Object* other = p.child("integrator", "", true)) fail(*other, "a second integrator");
    // Objects declared at the top with an id, used through <ref>: each is mapped
    // where a shape uses it (as an emitter's surface, not at all).
    for (const Object* o = p.child("bsdf", "", true); o != nullptr; o = p.child("bsdf", "", true)) {
      if (o->id.empty()) fail(*o, "a <bsdf> at the scene's top level needs an id, to be referenced by shapes");
    }
    for (const Object* o = p.child("texture", "", true); o != nullptr; o = p.child("texture", "", true)) {
      if (o->id.empty()) fail(*o, "a <texture> at the scene's top level needs an id");
    }
    for (const Object* o = p.child("emitter", "", true); o != nullptr; o = p.child("emitter", "", true)) read_emitter(*o);
    for (const Object* o = p.child("shape", "", true); o != nullptr; o = p.child("shape", "", true)) {
      read_shape(*o, identity(), nullptr);
    }
    p.finish();
    doc_["render"] = render_;
    if (!have_sky_) doc_["sky"] = {{"type", "uniform"}, {"radiance", triple(0, 0, 0)}};
    if (!textures_.empty()) doc_["textures"] = textures_;
    doc_["materials"] = materials_;
    if (!spheres_.empty()) doc_["spheres"] = spheres_;
    if (!meshes_.empty()) doc_["meshes"] = meshes_;
    if (!instances_.empty()) doc_["instances"] = instances_;
    if (!lights_.empty()) doc_["lights"] = lights_;
    if (!warnings_.empty()) doc_["warnings"] = warnings_;
    return doc_;
  }

 private:
  void warn(const Object& o, const std::string& what, int line = 0) {
    const std::string w = where(o, line) + ": " + what;
    if (std::find(warnings_.begin(), warnings_.end(), w) == warnings_.end()) warnings_.push_back(w);
  }

  // A file a plugin names, as Mitsuba resolves it (against the scene file's folder),
  // written relative to that folder; it must be a regular file.
  std::string file(Plugin& p, const std::string& name) {
    const Property* prop = p.object().find(name);
    const int line = prop != nullptr ? prop->line : 0;
    const std::string given = p.string(name, "");
    if (given.empty()) p.fail("'" + name + "' is required", line);
    const fs::path full = fs::path(given).is_absolute() ? fs::path(given) : base_ / given;
    std::error_code ec;
    if (!fs::exists(full, ec)) p.fail("file '" + given + "' does not exist", line);
    if (!fs::is_regular_file(full, ec)) p.fail("'" + given + "' is not a regular file", line);
    return fs::path(given).lexically_normal().generic_string();
  }

  std::string unique(const std::string& stem) {
    std::string name = stem;
    for (int n = 2; used_names_.count(name); ++n) name = stem + "#" + std::to_string(n);
    used_names_.insert(name);
    return name;
  }

  // What makes two objects one: the id it was given (a <ref> with a name of its own
  // is a copy of the object, the same object all the same), else the object itself.
  static std::string identity_of(const Object& o) {
    return o.id.empty() ? "at:" + std::to_string(reinterpret_cast<uintptr_t>(&o)) : "id:" + o.id;
  }

  static std::string label(const Object& o) {
    return o.id.empty() ? o.type + "@" + fs::path(o.file).filename().string() + ":" + std::to_string(o.line) : o.id;
  }

  // ---- sensor, film, sampler, integrator ----

  void read_sensor(const Object& o) {
    Plugin p(o);
    if (o.type != "perspective" && o.type != "thinlens") {
      p.fail("sensor type '" + o.type + "' is not supported (perspective and thinlens are)");
    }
    int width = 768, height = 576;
    if (const Object* film = p.child("film", "", true)) read_film(*film, width, height);
    if (const Object* sampler = p.child("sampler", "", true)) read_sampler(*sampler);
    const Matrix m = p.transform("to_world");
    const Vec3 origin = point_of(m, {0, 0, 0});
    const Vec3 forward = vector_of(m, {0, 0, 1}), up = vector_of(m, {0, 1, 0}), left = vector_of(m, {1, 0, 0});
    if (!(length(forward) > 0) || !(length(up) > 0)) p.fail("to_world is singular");
    if (dot(left, cross(up, forward)) <= 0) {
      p.fail("to_world mirrors the image (its determinant is negative): a mirrored camera is not supported");
    }
    double fov = 0;
    std::string axis;
    if (p.has("fov")) {
      if (p.has("focal_length")) p.fail("give 'fov' or 'focal_length', not both");
      fov = p.number("fov", -1);
      if (!(fov > 0 && fov < 180)) p.fail("'fov' must be in (0, 180) degrees");
      axis = p.string("fov_axis", "x");
    } else {
      // A 35 mm film's focal length (default 50mm): the angle its diagonal (36 x 24
      // mm) spans, on the film's diagonal, as Mitsuba reads it.
      const std::string given = p.string("focal_length", "50mm");
      char* end = nullptr;
      const double f = std::strtod(given.c_str(), &end);
      if (!(f > 0) || !(std::string(end) == "mm" || std::string(end).empty())) {
        p.fail("focal_length '" + given + "' is not a length in mm (\"50mm\")");
      }
      fov = 2 * std::atan(std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2 * f)) * kDegrees;
      axis = "diagonal";
      p.ignore("fov_axis");
    }
    const double t = std::tan(fov / 2 / kDegrees), w = width, h = height;
    double tv = t;
    if (axis == "x" || (axis == "smaller" && w <= h) || (axis == "larger" && w > h)) {
      tv = t * h / w;
    } else if (axis == "diagonal") {
      tv = t * h / std::sqrt(w * w + h * h);
    } else if (!(axis == "y" || axis == "smaller" || axis == "larger")) {
      p.fail("fov_axis '" + axis + "' is not one of x, y, diagonal, smaller, larger");
    }
    // Read and not applied: a camera ray starts at the lens and is not cut off.
    p.ignore("near_clip");
    p.ignore("far_clip");
    json camera = {{"look_from", triple(origin)},
                   {"look_at", triple(origin.x + forward.x, origin.y + forward.y, origin.z + forward.z)},
                   {"up", triple(scaled(up, 1.0 / length(up)))},
                   {"vfov", 2 * std::atan(tv) * kDegrees}};
    if (o.type == "thinlens") {
      const double radius = p.number("aperture_radius", -1);
      if (!(radius >= 0)) p.fail("'aperture_radius' is required (>= 0)");
      const double focus = p.number("focus_distance", -1);
      if (!(focus > 0)) p.fail("'focus_distance' is required (> 0)");
      camera["aperture"] = 2 * radius;  // a diameter in wavetrace
      camera["focus_distance"] = focus;
    }
    p.finish();
    doc_["camera"] = camera;
    render_["width"] = width;
    render_["height"] = height;
  }

  void read_film(const Object& o, int& width, int& height) {
    Plugin p(o);
    if (o.type != "hdrfilm") p.fail("film type '" + o.type + "' is not supported (hdrfilm is)");
    width = static_cast<int>(p.number("width", 768));
    height = static_cast<int>(p.number("height", 576));
    // What the output file holds is the command line's choice (-o).
    for (const char* name : {"file_format", "pixel_format", "component_format", "banner", "sample_border"}) p.ignore(name);
    if (const Object* f = p.child("rfilter", "", true)) {
      Plugin rf(*f);
      if (f->type != "box") {
        warn(*f, "the reconstruction filter '" + f->type + "' is rendered as box (each sample counts in its own pixel)");
        rf.ignore("radius");
        rf.ignore("stddev");
        rf.ignore("B");
        rf.ignore("C");
        rf.ignore("lobes");
      }
      rf.finish();
    } else {
      warn(o, "no rfilter: Mitsuba's default (gaussian) is rendered as box");
    }
    p.finish();
  }

  void read_sampler(const Object& o) {
    Plugin p(o);
    static const std::set<std::string> samplers = {"independent", "stratified", "multijitter", "orthogonal", "ldsampler"};
    if (!samplers.count(o.type)) p.fail("sampler type '" + o.type + "' is not supported");
    render_["spp"] = static_cast<int64_t>(p.number("sample_count", 4));
    if (p.has("seed")) render_["seed"] = static_cast<int64_t>(p.number("seed", 0));
    p.ignore("jitter");  // the pattern, not what it converges to
    p.ignore("strength");
    p.finish();
  }

  void read_integrator(const Object* o) {
    int64_t depth = -1, rr = 5;
    if (o != nullptr) {
      Plugin p(*o);
      if (o->type == "path") {
        depth = static_cast<int64_t>(p.number("max_depth", -1));
        rr = static_cast<int64_t>(p.number("rr_depth", 5));
      } else if (o->type == "direct") {
        depth = 2;  // the camera ray and one bounce, lit by light samples and BSDF samples
        // The sample counts change the noise, not what the render converges to.
        p.ignore("emitter_samples");
        p.ignore("bsdf_samples");
        p.ignore("shading_samples");
      } else {
        p.fail("integrator type '" + o->type + "' is not supported (path and direct are)");
      }
      if (p.boolean("hide_emitters", false)) p.fail("'hide_emitters' true is not supported");
      p.finish();
      if (depth == 0 || depth < -1) p.fail("max_depth must be -1 or at least 1");
      if (depth == -1 || depth > 1024) {
        warn(*o, "max_depth " + std::to_string(depth) + " is rendered to wavetrace's deepest, 1024 segments");
        depth = 1024;
      }
      if (rr < 0) p.fail("rr_depth must be >= 0");
    } else {
      depth = 1024;
    }
    render_["depth"] = depth;
    render_["roulette_depth"] = rr;
    render_["nee"] = 1;
  }

  // ---- textures ----

  // A UV transform (to_uv) as wavetrace's scale, then rotation, then offset.
  void uv_transform(Plugin& p, json& t) {
    const Matrix m = p.transform("to_uv");
    if (is_identity(m)) return;
    const double a = m[0], b = m[1], c = m[4], d = m[5];
    const double sx = std::sqrt(a * a + c * c);
    if (!(sx > 0)) p.fail("to_uv is singular");
    const double cs = a / sx, sn = -c / sx;
    const double sy = cs * d + sn * b;
    if (std::fabs(b - sn * sy) > 1e-6 * (std::fabs(sy) + 1) || std::fabs(d - cs * sy) > 1e-6 * (std::fabs(sy) + 1) ||
        !(std::fabs(sy) > 0)) {
      p.fail("to_uv shears the texture: only scale, rotation and translation are supported");
    }
    t["uv_scale"] = json::array({sx, sy});
    t["uv_rotation"] = std::atan2(sn, cs);
    t["uv_offset"] = json::array({m[3], m[7]});
  }

  // The texture `o` as a wavetrace texture's name. `linear`: where it holds vectors
  // or heights (a normal or bump map), whose bitmap must be read raw.
  std::string texture_name(const Object& o, bool linear, const std::string& use) {
    const auto key = std::make_pair(identity_of(o), linear);
    if (auto it = textures_of_.find(key); it != textures_of_.end()) return it->second;
    Plugin p(o);
    json t;
    if (o.type == "bitmap") {
      t["type"] = "image";
      t["file"] = file(p, "filename");
      const bool raw = p.boolean("raw", false);
      if (linear && !raw) p.fail("a " + use + " holds vectors or heights: read its bitmap raw (<boolean name=\"raw\" value=\"true\"/>)");
      t["colorspace"] = raw ? "linear" : "srgb";
      const std::string filter = p.string("filter_type", "bilinear");
      if (filter != "bilinear" && filter != "nearest") p.fail("filter_type '" + filter + "' is not bilinear or nearest");
      t["filter"] = filter;
      const std::string wrap = p.string("wrap_mode", "repeat");
      if (wrap != "repeat" && wrap != "mirror" && wrap != "clamp") p.fail("wrap_mode '" + wrap + "' is not repeat, mirror or clamp");
      t["wrap"] = wrap;
      p.ignore("format");  // the precision of the texels held
      uv_transform(p, t);
    } else if (o.type == "checkerboard") {
      t["type"] = "uv_checker";
      t["even"] = triple(p.colour("color0", Rgb{0.4, 0.4, 0.4}));
      t["odd"] = triple(p.colour("color1", Rgb{0.2, 0.2, 0.2}));
      uv_transform(p, t);
    } else {
      p.fail("texture type '" + o.type + "' is not supported (bitmap and checkerboard are)");
    }
    p.finish();
    const std::string name = unique("tex:" + label(o) + (linear ? ":linear" : ""));
    t["name"] = name;
    textures_.push_back(t);
    textures_of_[key] = name;
    return name;
  }

  // A colour parameter that a texture may give instead: sets `key` (the colour,
  // white under a texture) and `texture_key`.
  void colour_or_texture(Plugin& p, const std::string& name, const Rgb& fallback, json& m, const std::string& key,
                         const std::string& texture_key) {
    if (const Object* t = p.child("texture", name)) {
      m[key] = triple(1, 1, 1);
      m[texture_key] = texture_name(*t, false, name);
      return;
    }
    m[key] = triple(p.colour(name, fallback));
  }

  // A number that must not be textured here.
  double plain_number(Plugin& p, const std::string& name, double fallback) {
    if (p.nested(name)) p.fail("a texture for '" + name + "' is not supported (give a number)");
    return p.number(name, fallback);
  }

  // ---- BSDFs ----

  double ior(Plugin& p, const std::string& name, double fallback) {
    const Property* prop = p.object().find(name);
    if (prop != nullptr && std::holds_alternative<std::string>(prop->value)) {
      const std::string n = p.string(name, "");
      const auto it = named_iors().find(n);
      if (it == named_iors().end()) p.fail("unknown index of refraction '" + n + "'", prop->line);
      return it->second;
    }
    const double v = p.number(name, fallback);
    if (!(v > 0)) p.fail("'" + name + "' must be > 0", prop != nullptr ? prop->line : 0);
    return v;
  }

  // The microfacet roughness of a rough BSDF: sets roughness (and anisotropy) and
  // returns the GGX alpha (of the two, their geometric mean).
  double roughness(Plugin& p, json& m, bool anisotropic_allowed) {
    const std::string distribution = p.string("distribution", "beckmann");
    if (distribution == "beckmann") {
      warn(p.object(), "the Beckmann distribution is rendered as GGX of the same alpha");
    } else if (distribution != "ggx") {
      p.fail("distribution '" + distribution + "' is not ggx or beckmann");
    }
    p.ignore("sample_visible");  // how it is sampled, not what it converges to
    double alpha = 0.1;
    if (p.has("alpha_u") || p.has("alpha_v")) {
      if (p.has("alpha")) p.fail("give 'alpha' or 'alpha_u' and 'alpha_v', not both");
      if (!anisotropic_allowed) p.fail("'alpha_u' and 'alpha_v' are not supported here");
      const double au = plain_number(p, "alpha_u", 0.1), av = plain_number(p, "alpha_v", 0.1);
      if (!(au > 0 && av > 0 && au <= 1 && av <= 1)) p.fail("alpha_u and alpha_v must be in (0, 1]");
      if (av > au) {
        p.fail("alpha_v > alpha_u (rougher across the tangent than along it) is not supported");
      }
      const double anisotropy = (1 - av / au) / 0.9;
      if (anisotropy > 1) p.fail("alpha_v / alpha_u below 0.1 is not supported (wavetrace's anisotropy reaches 10:1)");
      alpha = std::sqrt(au * av);
      if (anisotropy > 0) m["anisotropy"] = anisotropy;
    } else {
      alpha = plain_number(p, "alpha", 0.1);
      if (!(alpha >= 0 && alpha <= 1)) p.fail("alpha must be in [0, 1]");
    }
    m["roughness"] = std::sqrt(alpha);
    return alpha;
  }

  void unit_reflectance(Plugin& p, const char* name) {
    if (p.nested(name)) p.fail(std::string("a texture for '") + name + "' is not supported");
    const Rgb c = p.colour(name, Rgb{1, 1, 1});
    if (c.r != 1 || c.g != 1 || c.b != 1) p.fail(std::string("'") + name + "' other than 1 is not supported");
  }

  Surface bsdf(const Object& o) {
    Plugin p(o);
    Surface s;
    json& m = s.material;
    const std::string& type = o.type;
    if (type == "twosided") {
      // wavetrace's reflecting surfaces are two-sided already (docs/scene-format.md).
      const Object* inner = p.child("bsdf", "", true);
      if (inner == nullptr) p.fail("needs a nested <bsdf>");
      if (p.child("bsdf", "", true) != nullptr) p.fail("two different BSDFs for the two sides are not supported");
      p.finish();
      return bsdf(*inner);
    }
    if (type == "mask") {
      const Object* inner = p.child("bsdf", "", true);
      if (inner == nullptr) p.fail("needs a nested <bsdf>");
      json alpha = {{"mode", "blend"}};
      if (const Object* t = p.child("texture", "opacity")) {
        alpha["texture"] = texture_name(*t, false, "opacity");
        alpha["channel"] = "luminance";
      } else {
        const double v = p.number("opacity", 0.5);
        if (!(v >= 0 && v <= 1)) p.fail("opacity must be in [0, 1]");
        alpha["opacity"] = v;
      }
      p.finish();
      s = bsdf(*inner);
      if (!s.alpha.is_null()) p.fail("a mask within a mask is not supported");
      s.alpha = alpha;
      return s;
    }
    if (type == "normalmap" || type == "bumpmap") {
      const Object* inner = p.child("bsdf", "", true);
      if (inner == nullptr) p.fail("needs a nested <bsdf>");
      const Object* t = type == "normalmap" ? p.child("texture", "normalmap") : p.child("texture", "", true);
      if (t == nullptr) p.fail(type == "normalmap" ? "needs a <texture name=\"normalmap\">" : "needs a nested <texture>");
      const double scale = type == "bumpmap" ? p.number("scale", 1.0) : 1.0;
      // wavetrace's own rule for a mapped normal facing away (docs/scene-format.md),
      // and no shadowing term of the mapped normal's.
      p.ignore("flip_invalid_normals");
      if (p.boolean("use_shadowing_function", false)) {
        warn(o, "use_shadowing_function: the mapped normal's shadowing term is not applied");
      }
      p.finish();
      s = bsdf(*inner);
      if (s.material.value("type", "") == "emissive") p.fail("an emitter's surface takes no " + type);
      if (s.material.value("type", "") == "blend") {
        p.fail("a " + type + " around a blendbsdf is not supported (give each of its BSDFs the map)");
      }
      if (s.material.contains("normal_texture") || s.material.contains("bump_texture")) {
        p.fail("a normal or bump map on a surface that has one already is not supported");
      }
      const std::string tex = texture_name(*t, true, type == "normalmap" ? "normal map" : "bump map");
      if (type == "normalmap") {
        s.material["normal_texture"] = tex;
      } else {
        s.material["bump_texture"] = tex;
        s.material["bump_scale"] = scale;
      }
      return s;
    }
    if (type == "diffuse") {
      m["type"] = "lambertian";
      colour_or_texture(p, "reflectance", Rgb{0.5, 0.5, 0.5}, m, "albedo", "texture");
    } else if (type == "conductor" || type == "roughconductor") {
      m["type"] = "conductor";
      m["masking"] = "separable";
      m["energy_compensation"] = false;
      if (p.has("eta") || p.has("k")) {
        if (p.has("material")) p.fail("give 'material' or 'eta' and 'k', not both");
        if (p.nested("eta") || p.nested("k")) p.fail("a texture for eta or k is not supported");
        m["eta"] = triple(p.colour("eta", Rgb{0, 0, 0}));
        m["k"] = triple(p.colour("k", Rgb{1, 1, 1}));
      } else {
        const std::string metal = p.string("material", "none");
        if (metal == "none") {
          m["f0"] = triple(1, 1, 1);  // Mitsuba's perfect mirror
        } else {
          const auto it = named_metals().find(metal);
          if (it != named_metals().end()) {
            m["metal"] = it->second;
          } else if (const MitsubaMetal* named = mitsuba_metal(metal)) {
            m["eta"] = triple(named->eta.x, named->eta.y, named->eta.z);
            m["k"] = triple(named->k.x, named->k.y, named->k.z);
          } else {
            std::string known;
            for (const auto& [k, v] : named_metals()) known += (known.empty() ? "" : ", ") + k;
            p.fail("material '" + metal + "' is not one of Mitsuba's named conductors (" + known +
                   ", the other names of its data/ior folder, none): give eta and k");
          }
        }
      }
      const bool tinted_mirror = m.contains("f0") && !p.nested("specular_reflectance") && p.has("specular_reflectance");
      if (tinted_mirror) {
        // Mitsuba's perfect mirror tinted: reflects the tint at every angle, where
        // Schlick's f0 of the tint brightens towards grazing.
        const Rgb tint = p.colour("specular_reflectance", Rgb{1, 1, 1});
        if (tint.r > 1 || tint.g > 1 || tint.b > 1) p.fail("specular_reflectance must be at most 1");
        if (tint.r != 1 || tint.g != 1 || tint.b != 1) {
          m["f0"] = triple(tint);
          warn(o, "specular_reflectance of material none is rendered as Schlick's f0 (the same at normal incidence, "
                  "brighter towards grazing)");
        }
      } else {
        unit_reflectance(p, "specular_reflectance");
      }
      if (type == "roughconductor") {
        roughness(p, m, true);
      } else {
        m["roughness"] = 0;
      }
    } else if (type == "dielectric" || type == "roughdielectric" || type == "thindielectric") {
      m["type"] = "glass";
      m["masking"] = "separable";
      m["energy_compensation"] = false;
      const double eta = ior(p, "int_ior", named_iors().at("bk7")) / ior(p, "ext_ior", named_iors().at("air"));
      m["ior"] = eta;
      unit_reflectance(p, "specular_reflectance");
      if (p.nested("specular_transmittance")) p.fail("a texture for 'specular_transmittance' is not supported");
      m["tint"] = triple(p.colour("specular_transmittance", Rgb{1, 1, 1}));
      if (type == "roughdielectric") {
        roughness(p, m, false);
      } else {
        m["roughness"] = 0;
      }
      if (type == "thindielectric") m["thin"] = true;
    } else if (type == "plastic" || type == "roughplastic" || type == "phong") {
      m["type"] = "plastic";
      m["masking"] = "separable";
      m["energy_compensation"] = false;
      double eta = 1.5, alpha = 0;
      bool nonlinear = true;
      if (type == "phong") {
        const double exponent = plain_number(p, "exponent", 30);
        if (!(exponent >= 0)) p.fail("exponent must be >= 0");
        // The Beckmann alpha of the same mean-square slope (Walter et al. 2007).
        alpha = std::min(1.0, std::sqrt(2 / (exponent + 2)));
        m["roughness"] = std::sqrt(alpha);
        if (p.nested("specular_reflectance")) p.fail("a texture for 'specular_reflectance' is not supported");
        p.colour("specular_reflectance");
        warn(o, "phong is rendered as the nearest roughplastic (GGX alpha sqrt(2 / (exponent + 2)), ior 1.5, its "
                "specular_reflectance not applied)");
        colour_or_texture(p, "diffuse_reflectance", Rgb{0.5, 0.5, 0.5}, m, "albedo", "texture");
      } else {
        eta = ior(p, "int_ior", named_iors().at("polypropylene")) / ior(p, "ext_ior", named_iors().at("air"));
        unit_reflectance(p, "specular_reflectance");
        colour_or_texture(p, "diffuse_reflectance", Rgb{0.5, 0.5, 0.5}, m, "albedo", "texture");
        nonlinear = p.boolean("nonlinear", false);
        if (type == "roughplastic") {
          alpha = roughness(p, m, false);
        } else {
          m["roughness"] = 0;
        }
      }
      m["ior"] = eta;
      if (!nonlinear) {
        // Mitsuba's linear model divides the base by 1 - R_int, wavetrace's by
        // 1 - albedo R_int: the albedo a' = a / (1 - R_int + a R_int) (>= a, <= 1)
        // gives the same reflectance (exactly, for a constant albedo).
        if (m.contains("texture")) {
          warn(o, "nonlinear false with a textured diffuse_reflectance is rendered as nonlinear");
        } else {
          const double r = plastic_internal_reflectance(static_cast<float>(eta), Ggx{static_cast<float>(alpha), static_cast<float>(alpha), true});
          json a = json::array();
          for (const json& c : m["albedo"]) {
            const double v = c.get<double>();
            a.push_back(v / (1 - r + v * r));
          }
          m["albedo"] = a;
        }
      }
    } else if (type == "principled") {
      principled(p, m);
    } else if (type == "blendbsdf") {
      // wavetrace's blend: the first BSDF at weight 0, the second at weight 1.
      m["type"] = "blend";
      if (const Object* t = p.child("texture", "weight")) {
        m["weight"] = 1;
        m["weight_texture"] = texture_name(*t, false, "weight");
      } else {
        const double w = p.number("weight", 0.5);
        if (!(w >= 0 && w <= 1)) p.fail("weight must be in [0, 1]");
        m["weight"] = w;
      }
      json names = json::array();
      for (int i = 0; i < 2; ++i) {
        const Object* inner = p.child("bsdf", "", true);
        if (inner == nullptr) p.fail("needs two nested BSDFs");
        const auto [name, alpha] = material(inner);
        if (!alpha.is_null()) fail(*inner, "a mask within a blendbsdf is not supported (put the mask around the blend)");
        names.push_back(name);
      }
      if (p.child("bsdf", "", true) != nullptr) p.fail("takes two nested BSDFs, not more");
      m["materials"] = names;
    } else {
      p.fail("BSDF type '" + type + "' is not supported");
    }
    p.finish();
    return s;
  }

  // Mitsuba's principled BSDF (Disney's parameters) as glTF's, where they mean the same.
  void principled(Plugin& p, json& m) {
    m["type"] = "principled";
    m["masking"] = "separable";
    m["energy_compensation"] = false;
    colour_or_texture(p, "base_color", Rgb{0.5, 0.5, 0.5}, m, "albedo", "texture");
    auto factor = [&](const std::string& name, double fallback, const std::string& key, const std::string& texture_key) {
      if (const Object* t = p.child("texture", name)) {
        if (texture_key.empty()) p.fail("a texture for '" + name + "' is not supported");
        m[key] = 1;
        m[texture_key] = texture_name(*t, false, name);
        return -1.0;
      }
      const double v = p.number(name, fallback);
      if (!(v >= 0 && v <= 1)) p.fail("'" + name + "' must be in [0, 1]");
      m[key] = v;
      return v;
    };
    factor("roughness", 0.5, "roughness", "roughness_texture");
    factor("metallic", 0.0, "metallic", "metallic_texture");
    factor("anisotropic", 0.0, "anisotropy", "");
    if (factor("spec_trans", 0.0, "transmission", "transmission_texture") != 0) m["thin"] = false;
    if (p.has("eta")) {
      m["ior"] = plain_number(p, "eta", 1.5);
      p.ignore("specular");
    } else {
      const double specular = plain_number(p, "specular", 0.5);
      m["ior"] = 2 / (1 - std::sqrt(0.08 * specular)) - 1;
    }
    const double clearcoat = plain_number(p, "clearcoat", 0);
    const double gloss = plain_number(p, "clearcoat_gloss", 0);
    if (clearcoat > 0) {
      // Disney's coat: a quarter of the weight, GTR1 of alpha lerp(0.1, 0.001, gloss).
      m["clearcoat"] = 0.25 * clearcoat;
      m["clearcoat_roughness"] = std::sqrt(0.1 + (0.001 - 0.1) * gloss);
      warn(p.object(), "clearcoat: Disney's GTR1 coat is rendered as a GGX coat of the same alpha and a quarter of the weight");
    }
    for (const char* name : {"sheen", "sheen_tint", "spec_tint", "flatness"}) {
      if (plain_number(p, name, 0) != 0) p.fail(std::string("'") + name + "' other than 0 is not supported");
    }
    p.ignore("sample_visible");
    m["double_sided"] = true;
  }

  // The material a shape's BSDF (or its absence: Mitsuba's diffuse 0.5) means, by
  // name, and its alpha.
  std::pair<std::string, json> material(const Object* o) {
    if (o == nullptr) {
      if (default_material_.empty()) {
        default_material_ = unique("diffuse:default");
        materials_.push_back({{"name", default_material_}, {"type", "lambertian"}, {"albedo", triple(0.5, 0.5, 0.5)}});
      }
      return {default_material_, json()};
    }
    const auto it = materials_of_.find(identity_of(*o));
    if (it != materials_of_.end()) return it->second;
    Surface s = bsdf(*o);
    const std::string name = unique(label(*o));
    s.material["name"] = name;
    materials_.push_back(s.material);
    return materials_of_[identity_of(*o)] = {name, s.alpha};
  }
  std::string emissive(const Object& emitter) {
    Plugin p(emitter);
    p.ignore("sampling_weight");  // how often it is sampled, not what the image converges to
    json m = {{"type", "emissive"}};
    if (const Object* t = p.child("texture", "radiance")) {
      m["emission"] = triple(1, 1, 1);
      m["emission_texture"] = texture_name(*t, false, "radiance");
    } else {
      const std::optional<Rgb> c = p.colour("radiance");
      if (!c) p.fail("'radiance' is required");
      m["emission"] = triple(*c);
    }
    p.finish();
    const std::string name = unique("emitter:" + label(emitter));
    m["name"] = name;
    materials_.push_back(m);
    return name;
  }

  // A BSDF that reflects nothing (a diffuse or conductor of reflectance 0): an
  // emitter's surface as wavetrace's emitters are.
  static bool black(const Object& b) {
    if (b.type == "twosided" && b.children.size() == 1) return black(*b.children[0]);
    const char* key = b.type == "diffuse" ? "reflectance" : (b.type == "conductor" ? "specular_reflectance" : nullptr);
    const Property* p = key != nullptr ? b.find(key) : nullptr;
    const Rgb* c = p != nullptr ? std::get_if<Rgb>(&p->value) : nullptr;
    return c != nullptr && c->r == 0 && c->g == 0 && c->b == 0;
  }

  // ---- emitters ----

  void sky(const Object& o, const json& s) {
    if (have_sky_) fail(o, "a second environment emitter is not supported (one sky a scene)");
    have_sky_ = true;
    doc_["sky"] = s;
  }

  void read_emitter(const Object& o) {
    Plugin p(o);
    const std::string& type = o.type;
    if (type == "constant") {
      if (p.nested("radiance")) p.fail("a texture for 'radiance' is not supported");
      const Rgb radiance = p.colour("radiance", Rgb{1, 1, 1});
      p.finish();
      sky(o, {{"type", "uniform"}, {"radiance", triple(radiance)}});
      return;
    }
    if (type == "envmap") {
      json s = {{"type", "environment"}, {"file", file(p, "filename")}, {"mapping", "latlong"}};
      const double scale = p.number("scale", 1.0);
      if (!(scale >= 0)) p.fail("scale must be >= 0");
      s["intensity"] = scale;
      const Matrix m = p.transform("to_world");
      // Only a turn about +y: R_y(t) = [c 0 s; 0 1 0; -s 0 c].
      const double c = m[0], sn = m[2];
      const double e = std::fabs(m[1]) + std::fabs(m[4]) + std::fabs(m[6]) + std::fabs(m[9]) + std::fabs(m[5] - 1) +
                       std::fabs(m[10] - c) + std::fabs(m[8] + sn) + std::fabs(m[3]) + std::fabs(m[7]) + std::fabs(m[11]);
      if (e > 1e-6 || std::fabs(c * c + sn * sn - 1) > 1e-6) {
        p.fail("to_world other than a rotation about +y is not supported for an envmap");
      }
      if (!is_identity(m)) s["rotation"] = std::atan2(sn, c) * kDegrees;
      p.ignore("mis_compensation");
      p.finish();
      sky(o, s);
      return;
    }
    json l = {{"type", type}};
    if (type == "point") {
      const Matrix m = p.transform("to_world");
      const Vec3 at = p.point("position", Vec3{0, 0, 0});
      l["position"] = triple(point_of(m, at));
      l["intensity"] = triple(p.colour("intensity", Rgb{1, 1, 1}));
    } else if (type == "spot") {
      const Matrix m = p.transform("to_world");
      l["position"] = triple(point_of(m, {0, 0, 0}));
      const Vec3 d = vector_of(m, {0, 0, 1});
      if (!(length(d) > 0)) p.fail("to_world is singular");
      l["direction"] = triple(scaled(d, 1 / length(d)));
      l["intensity"] = triple(p.colour("intensity", Rgb{1, 1, 1}));
      const double cutoff = p.number("cutoff_angle", 20);
      const double beam = p.number("beam_width", cutoff * 3 / 4);
      if (!(cutoff > 0 && cutoff <= 90 && beam >= 0 && beam < cutoff)) {
        p.fail("cutoff_angle must be in (0, 90] and beam_width in [0, cutoff_angle)");
      }
      l["inner_angle"] = beam;
      l["outer_angle"] = cutoff;
    } else if (type == "directional") {
      const Matrix m = p.transform("to_world");
      Vec3 d = p.point("direction", Vec3{0, 0, 1});
      d = vector_of(m, d);
      if (!(length(d) > 0)) p.fail("the direction is zero");
      l["direction"] = triple(scaled(d, 1 / length(d)));
      l["irradiance"] = triple(p.colour("irradiance", Rgb{1, 1, 1}));
    } else if (type == "area") {
      p.fail("an area emitter belongs in a <shape>");
    } else if (type == "sunsky" || type == "sky" || type == "sun") {
      p.fail("not supported: wavetrace has no model of the sun and sky (give an envmap)");
    } else {
      p.fail("emitter type '" + type + "' is not supported");
    }
    p.finish();
    lights_.push_back(l);
  }

  // ---- shapes ----

  // A mesh entry for the file or built-in shape, read once however often placed.
  std::string mesh(json entry) {
    const std::string key = entry.dump();
    if (auto it = meshes_of_.find(key); it != meshes_of_.end()) return it->second;
    const std::string name = unique("mesh:" + entry.value("file", entry.value("shape", std::string())) +
                                    (entry.contains("shape_index") ? "#" + entry["shape_index"].dump() : ""));
    entry["name"] = name;
    meshes_.push_back(entry);
    return meshes_of_[key] = name;
  }

  void place(const std::string& mesh_name, const Matrix& m) {
    json in = {{"mesh", mesh_name}};
    if (!is_identity(m)) in["matrix"] = json(std::vector<double>(m.begin(), m.end()));
    instances_.push_back(in);
  }

  // `group`: the shapegroup it belongs to (its shapes are placed by its instances).
  void read_shape(const Object& o, const Matrix& parent, std::vector<std::pair<std::string, Matrix>>* group) {
    Plugin p(o);
    const std::string& type = o.type;
    if (type == "shapegroup") {
      if (group != nullptr) p.fail("a shapegroup within a shapegroup is not supported");
      if (o.id.empty()) p.fail("a shapegroup needs an id, for its instances");
      std::vector<std::pair<std::string, Matrix>> members;
      for (const Object* s = p.child("shape", "", true); s != nullptr; s = p.child("shape", "", true)) {
        read_shape(*s, identity(), &members);
      }
      p.finish();
      groups_[identity_of(o)] = members;
      return;
    }
    if (type == "instance") {
      if (group != nullptr) p.fail("an instance within a shapegroup is not supported");
      const Object* g = p.child("shape", "", true);
      if (g == nullptr || g->type != "shapegroup") p.fail("needs a <ref> to a shapegroup");
      if (!groups_.count(identity_of(*g))) read_shape(*g, identity(), nullptr);
      const Matrix m = multiply(parent, p.transform("to_world"));
      p.finish();
      for (const auto& [name, own] : groups_.at(identity_of(*g))) place(name, multiply(m, own));
      return;
    }
    const Matrix m = multiply(parent, p.transform("to_world"));
    std::string material;
    json alpha;
    const Object* emitter = p.child("emitter", "", true);
    const Object* b = p.child("bsdf", "", true);
    if (emitter != nullptr) {
      if (emitter->type != "area") fail(*emitter, "only an area emitter can be attached to a shape");
      if (group != nullptr) fail(*emitter, "an emitter in a shapegroup is not supported");
      material = emissive(*emitter);
      if (b != nullptr && !black(*b)) {
        warn(o, "an area light's surface emits and does not also reflect (its bsdf is not rendered)");
      }
    } else {
      std::tie(material, alpha) = this->material(b);
    }
    if (type == "sphere") {
      if (p.boolean("flip_normals", false)) p.fail("flip_normals is not supported on a sphere");
      if (!alpha.is_null()) p.fail("a mask on a sphere is not supported");
      if (group != nullptr) p.fail("a sphere in a shapegroup is not supported (wavetrace's spheres stand untransformed)");
      const Vec3 c = point_of(m, p.point("center", Vec3{0, 0, 0}));
      const double r = p.number("radius", 1.0);
      const Vec3 x = vector_of(m, {1, 0, 0}), y = vector_of(m, {0, 1, 0}), z = vector_of(m, {0, 0, 1});
      const double s = length(x);
      const double tol = 1e-6 * s;
      if (std::fabs(length(y) - s) > tol || std::fabs(length(z) - s) > tol || std::fabs(dot(x, y)) > tol * s ||
          std::fabs(dot(y, z)) > tol * s || std::fabs(dot(x, z)) > tol * s) {
        p.fail("to_world must scale a sphere alike in every direction");
      }
      p.finish();
      spheres_.push_back({{"center", triple(c)}, {"radius", r * s}, {"material", material}});
      return;
    }
    json entry;
    static const std::set<std::string> built_in = {"rectangle", "cube", "disk", "cylinder"};
    if (type == "obj" || type == "ply" || type == "serialized") {
      entry["file"] = file(p, "filename");
      if (type == "obj" && !p.boolean("flip_tex_coords", true)) p.fail("flip_tex_coords false is not supported");
      if (type == "serialized") {
        const double index = p.number("shape_index", 0);
        if (index != 0) entry["shape_index"] = index;
      }
      if (p.boolean("face_normals", false)) entry["face_normals"] = true;
    } else if (built_in.count(type)) {
      entry["shape"] = type;
      if (type == "cylinder") {
        // Mitsuba's cylinder from p0 to p1 of `radius`: the unit one, placed.
        const Vec3 p0 = p.point("p0", Vec3{0, 0, 0}), p1 = p.point("p1", Vec3{0, 0, 1});
        const double radius = p.number("radius", 1.0);
        const Vec3 axis{p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
        const double len = length(axis);
        if (!(len > 0) || !(radius > 0)) p.fail("p0 and p1 must differ and radius be > 0");
        const Vec3 w = scaled(axis, 1 / len);
        const Vec3 helper = std::fabs(w.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        Vec3 u = cross(helper, w);
        u = scaled(u, 1 / length(u));
        const Vec3 v = cross(w, u);
        const Matrix local = {u.x * radius, v.x * radius, w.x * len, p0.x, u.y * radius, v.y * radius, w.y * len, p0.y,
                              u.z * radius, v.z * radius, w.z * len, p0.z, 0, 0, 0, 1};
        place_shape(p, entry, material, alpha, multiply(m, local), group);
        return;
      }
    } else {
      p.fail("shape type '" + type + "' is not supported");
    }
    place_shape(p, entry, material, alpha, m, group);
  }

  void place_shape(Plugin& p, json& entry, const std::string& material, const json& alpha, const Matrix& m,
                   std::vector<std::pair<std::string, Matrix>>* group) {
    if (p.boolean("flip_normals", false)) entry["flip_normals"] = true;
    entry["material"] = material;
    if (!alpha.is_null()) entry["alpha"] = alpha;
    p.finish();
    const std::string name = mesh(entry);
    if (group != nullptr) {
      group->emplace_back(name, m);
    } else {
      place(name, m);
    }
  }

  const Object& scene_;
  fs::path base_;
  json doc_ = json::object();
  json render_ = json::object();
  json textures_ = json::array(), materials_ = json::array(), spheres_ = json::array(), meshes_ = json::array(),
       instances_ = json::array(), lights_ = json::array();
  std::vector<std::string> warnings_;
  std::set<std::string> used_names_;
  std::map<std::pair<std::string, bool>, std::string> textures_of_;
  std::map<std::string, std::pair<std::string, json>> materials_of_;
  std::map<std::string, std::string> meshes_of_;
  std::map<std::string, std::vector<std::pair<std::string, Matrix>>> groups_;
  std::string default_material_;
  bool have_sky_ = false;
};

}  // namespace

json to_wavetrace(const Object& scene) { return Converter(scene).run(); }

json read_mitsuba_scene(const std::string& path, const std::map<std::string, std::string>& defines) {
  return to_wavetrace(*read_scene_xml(path, defines));
}

bool is_mitsuba_scene(const std::string& path) {
  return lower_extension(path) == ".xml";
}

void rebase_paths(json& document, const std::string& from, const std::string& to) {
  const fs::path target = fs::absolute(to).lexically_normal();
  auto rebase = [&](json& field) {
    const fs::path given = field.get<std::string>();
    if (given.is_absolute()) return;
    const fs::path full = fs::absolute(fs::path(from) / given).lexically_normal();
    field = full.lexically_relative(target).generic_string();
  };
  for (const char* list : {"textures", "meshes"}) {
    if (!document.contains(list)) continue;
    for (json& entry : document[list]) {
      if (entry.contains("file")) rebase(entry["file"]);
    }
  }
  if (document.contains("sky") && document["sky"].contains("file")) rebase(document["sky"]["file"]);
}

}  // namespace wt::mitsuba
