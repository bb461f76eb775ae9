// Mitsuba 3 XML scenes, read as their format is documented: the first layer, which
// turns a file into a tree of plugin objects with typed properties, before any of
// them means a wavetrace material or shape (issue 26).
//
// What this layer does:
// - `<default name value>` gives a parameter a value unless the caller set it
//   (`-D name=value`); `$name` in any attribute is replaced by the parameter's value;
// - `<include filename>` reads another file's `<scene>` children in place (relative
//   to the including file's folder; a file that includes itself, directly or not, is
//   an error);
// - `id` attributes name objects; `<ref id name>` puts the named object where it
//   stands (an unknown id, or an id given twice, is an error);
// - properties: `<float>`, `<integer>`, `<boolean>`, `<string>`, `<rgb>` (one value or
//   three), `<spectrum>` (one value: a grey; or wavelength:value pairs, reduced to
//   RGB by spectrum_to_rgb), `<point>` and `<vector>` (`value` or
//   `x`, `y`, `z`), and `<transform>` whose children (`translate`, `rotate`, `scale`,
//   `matrix`, `lookat`) each multiply the matrix from the left, in the order given;
// - every error is one InputError "<file>:<line>: <element>: <what>".
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace wt::mitsuba {

// A 4 x 4 matrix, row-major: m[4 * row + column]; points are columns (M p).
using Matrix = std::array<double, 16>;
Matrix identity();
Matrix multiply(const Matrix& a, const Matrix& b);  // a * b

struct Rgb {
  double r = 0, g = 0, b = 0;
};
struct Vec3 {
  double x = 0, y = 0, z = 0;
};

using Value = std::variant<double, int64_t, bool, std::string, Rgb, Vec3, Matrix>;

// A spectrum given as (wavelength in nm, value) samples, rising, read linearly between
// them and 0 outside, as linear sRGB: integrated over 360..830 nm against the CIE 1931
// colour matching functions (Wyman, Sloan and Shirley's analytic fit), taken to sRGB,
// and each channel divided by that of the constant spectrum 1, so that a flat
// spectrum over 360..830 nm is its grey. (A reflectance's colour under an
// equal-energy white; Mitsuba's own reduction may weigh an emitter's by D65.)
Rgb spectrum_to_rgb(const std::vector<std::pair<double, double>>& samples);

struct Property {
  std::string name;
  Value value;
  std::string kind;  // the element it came from: "float", "rgb", "transform", ...
  int line = 0;
};

// A plugin object: `<bsdf type="diffuse" id="white">`, with its properties and the
// objects nested in it (or referenced from it), in document order.
struct Object {
  std::string tag;   // "scene", "bsdf", "shape", "emitter", "sensor", "texture", ...
  std::string type;  // the plugin ("diffuse"); empty for the scene
  std::string id;    // empty where none was given
  std::string name;  // of a nested object: its `name` attribute ("reflectance"), if any
  std::string file;
  int line = 0;
  std::vector<Property> properties;
  std::vector<std::shared_ptr<const Object>> children;

  const Property* find(const std::string& property) const;
};

// Reads `path` (a `<scene>` document) with the parameters `defines` (-D name=value,
// which take precedence over its `<default>`s). Throws InputError naming the file,
// the line and the element.
std::shared_ptr<const Object> read_scene_xml(const std::string& path,
                                             const std::map<std::string, std::string>& defines = {});

}  // namespace wt::mitsuba
