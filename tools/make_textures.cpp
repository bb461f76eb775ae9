// wavetrace-textures OUTDIR
//
// Writes the five image textures that scenes/seed57.json uses: four 256 x 256
// "light probe" images in mirror-ball format and one 756 x 378
// latitude-longitude planet map; and sky_sun.hdr, a 512 x 256 latitude-longitude
// environment in linear radiance (a clear sky with a sun disc over dark ground)
// that lights scenes/sky-sun.json. They are made procedurally so that the project
// ships its own textures instead of depending on photographs it cannot
// redistribute. The sizes match the reference scene's textures so that texture
// memory traffic is comparable.
//
// Everything is a pure function of the pixel position (hashed gradient noise,
// no random state), so two runs write identical files.
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "wavetrace/texture.hpp"

namespace {

using wt::kPi;
using wt::vec2;
using wt::vec3;

struct Image8 {
  int width, height;
  std::vector<unsigned char> rgb;

  Image8(int w, int h) : width(w), height(h), rgb(static_cast<size_t>(w) * h * 3, 0) {}

  void set(int x, int y, const vec3& c) {
    unsigned char* p = &rgb[3 * (static_cast<size_t>(y) * width + x)];
    for (int k = 0; k < 3; ++k) {
      float v = std::min(std::max(c[k], 0.0f), 1.0f);
      p[k] = static_cast<unsigned char>(std::lround(v * 255.0f));
    }
  }
};

vec3 mix(const vec3& a, const vec3& b, float t) { return a + (b - a) * t; }

float smoothstep(float e0, float e1, float x) {
  float t = std::min(std::max((x - e0) / (e1 - e0), 0.0f), 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

float fract(float x) { return x - std::floor(x); }

// Signed fractal noise (unlike turbulence, which folds at zero): smooth shapes
// such as continents and clouds need both signs.
float fbm(vec3 p, int octaves) {
  float sum = 0.0f, weight = 1.0f;
  for (int i = 0; i < octaves; ++i) {
    sum += weight * wt::gradient_noise(p);
    weight *= 0.5f;
    p *= 2.03f;  // not exactly 2, so the octaves' lattices do not line up
  }
  return sum;
}

// Elevation above the horizon and azimuth of a unit direction (y up).
float elevation(const vec3& d) { return std::asin(std::min(std::max(d.y, -1.0f), 1.0f)); }
float azimuth(const vec3& d) { return std::atan2(d.x, d.z); }

// Where a downward direction meets the ground plane one unit below the
// viewpoint: patterns on floors and lawns are laid out there so that they
// shrink towards the horizon as in a photograph.
vec2 ground_point(const vec3& d) {
  float t = 1.0f / std::max(-d.y, 0.02f);
  return vec2(d.x * t, d.z * t);
}

// The same for a ceiling one unit above.
vec2 ceiling_point(const vec3& d) {
  float t = 1.0f / std::max(d.y, 0.02f);
  return vec2(d.x * t, d.z * t);
}

// A sun or lamp: a bright core with a soft glow around it.
float glow(const vec3& d, const vec3& centre, float core, float spread) {
  float c = glm::dot(d, centre);
  float angle = std::acos(std::min(std::max(c, -1.0f), 1.0f));
  return (angle < core ? 1.0f : 0.0f) + 0.5f * std::exp(-angle / spread);
}

// ---------------------------------------------------------------- environments

// Beach: open sky with a low sun, sea on one side, sand on the other.
vec3 beach(const vec3& d) {
  float el = elevation(d);
  if (el > 0.0f) {
    float h = std::pow(el / (0.5f * kPi), 0.45f);
    vec3 sky = mix(vec3(0.86f, 0.9f, 0.93f), vec3(0.18f, 0.42f, 0.85f), h);
    // Thin clouds stretched along one axis, like high cirrus.
    vec2 c = ceiling_point(d);
    float cloud = smoothstep(0.1f, 0.5f, fbm(vec3(c.x * 0.5f, c.y * 2.0f, 3.7f), 5));
    cloud *= smoothstep(0.0f, 0.15f, el);
    sky = mix(sky, vec3(0.97f), 0.8f * cloud);
    vec3 sun = glm::normalize(vec3(0.55f, 0.35f, -0.75f));
    sky += vec3(1.0f, 0.92f, 0.75f) * glow(d, sun, 0.05f, 0.12f);
    return sky;
  }
  // The shore is a wavy line on the ground plane; on one side of it, water.
  vec2 g = ground_point(d);
  float shore = 0.8f * g.x + 0.6f * g.y - 0.4f + 0.5f * fbm(vec3(g.x * 0.4f, g.y * 0.4f, 2.5f), 3);
  float depth = -el;  // small near the horizon
  if (shore > 0.0f) {
    float waves = wt::turbulence(vec3(g.x * 0.8f, 0.0f, g.y * 4.0f), 4);
    vec3 sea = mix(vec3(0.3f, 0.6f, 0.68f), vec3(0.04f, 0.25f, 0.4f), smoothstep(0.0f, 0.8f, depth));
    sea = mix(sea, vec3(0.9f, 0.95f, 0.97f), 0.5f * smoothstep(0.55f, 0.9f, waves));
    // A band of foam where the sea meets the sand.
    return mix(sea, vec3(0.93f), smoothstep(0.15f, 0.0f, shore));
  }
  float grain = wt::gradient_noise(vec3(g.x * 6.0f, g.y * 6.0f, 0.5f));
  vec3 sand = mix(vec3(0.88f, 0.78f, 0.58f), vec3(0.72f, 0.6f, 0.42f), 0.5f + 0.5f * grain);
  // Wet sand is darker next to the water.
  return mix(sand, vec3(0.55f, 0.47f, 0.35f), smoothstep(-0.25f, 0.0f, shore));
}

// Building: a tall stone hall with rows of bright windows between columns, a
// coffered ceiling with a skylight and a polished tile floor.
vec3 building(const vec3& d) {
  float el = elevation(d), az = azimuth(d);
  if (el < -0.02f) {
    vec2 g = ground_point(d);
    int parity = static_cast<int>(std::floor(g.x * 1.5f)) + static_cast<int>(std::floor(g.y * 1.5f));
    vec3 tile = (parity & 1) ? vec3(0.32f, 0.22f, 0.16f) : vec3(0.82f, 0.78f, 0.7f);
    float vein = wt::turbulence(vec3(g.x * 2.0f, g.y * 2.0f, 7.0f), 5);
    tile = mix(tile, vec3(0.5f, 0.45f, 0.4f), 0.35f * smoothstep(0.3f, 0.9f, vein));
    // The floor mirrors the bright windows a little.
    float reflect = smoothstep(-0.35f, -0.02f, el);
    return mix(tile, vec3(0.9f, 0.9f, 0.85f), 0.3f * reflect);
  }
  if (el > 1.05f) {
    vec2 c = ceiling_point(d);
    float gx = fract(c.x * 2.0f), gy = fract(c.y * 2.0f);
    float beam = (gx < 0.12f || gy < 0.12f) ? 1.0f : 0.0f;
    vec3 ceil = mix(vec3(0.45f, 0.36f, 0.28f), vec3(0.2f, 0.14f, 0.1f), beam);
    float sky = smoothstep(1.35f, 1.45f, el);
    return mix(ceil, vec3(0.95f, 0.97f, 1.0f), sky);
  }
  float bay = fract(az * (12.0f / (2.0f * kPi)));
  if (bay < 0.22f) {
    // Round columns: shading falls off across the column's width.
    float across = std::sin(kPi * bay / 0.22f);
    return vec3(0.78f, 0.72f, 0.62f) * (0.55f + 0.45f * across);
  }
  bool window = el > 0.08f && el < 0.75f && bay > 0.32f && bay < 0.9f;
  if (window) {
    // Mullions split each window into panes.
    float row = fract(el * 7.0f), col = fract((bay - 0.32f) / 0.58f * 3.0f);
    if (row < 0.08f || col < 0.06f) return vec3(0.18f, 0.16f, 0.15f);
    return mix(vec3(0.98f, 0.97f, 0.92f), vec3(0.7f, 0.8f, 0.95f), smoothstep(0.08f, 0.75f, el));
  }
  float stone = wt::gradient_noise(vec3(az * 8.0f, el * 8.0f, 2.0f));
  return mix(vec3(0.62f, 0.5f, 0.4f), vec3(0.5f, 0.4f, 0.32f), 0.5f + 0.5f * stone);
}

// Campus: cumulus clouds, a tree line and brick buildings on the horizon, a lawn
// crossed by a paved path.
vec3 campus(const vec3& d) {
  float el = elevation(d), az = azimuth(d);
  // Brick blocks occupy some ranges of azimuth; trees fill the rest.
  float block = wt::gradient_noise(vec3(az * 1.7f, 4.2f, 0.0f));
  bool is_block = block > 0.12f;
  float block_top = 0.16f + 0.1f * fract(std::floor(az * 4.0f) * 0.37f);
  float tree_top = 0.07f + 0.08f * wt::turbulence(vec3(az * 9.0f, 1.1f, 0.0f), 4);
  if (el >= 0.0f) {
    if (is_block && el < block_top) {
      float row = fract(el * 40.0f), col = fract(az * 40.0f);
      bool pane = row > 0.35f && row < 0.85f && col > 0.3f && col < 0.75f;
      return pane ? vec3(0.25f, 0.32f, 0.4f) : vec3(0.62f, 0.3f, 0.22f);
    }
    if (!is_block && el < tree_top) {
      float leaves = wt::turbulence(vec3(az * 30.0f, el * 30.0f, 0.0f), 3);
      return mix(vec3(0.1f, 0.3f, 0.08f), vec3(0.25f, 0.45f, 0.15f), std::min(leaves, 1.0f));
    }
    float h = std::pow(el / (0.5f * kPi), 0.6f);
    vec3 sky = mix(vec3(0.75f, 0.83f, 0.92f), vec3(0.25f, 0.48f, 0.82f), h);
    vec2 c = ceiling_point(d);
    float puff = fbm(vec3(c.x * 0.7f, c.y * 0.7f, 9.1f), 6);
    float cloud = smoothstep(0.05f, 0.35f, puff) * smoothstep(0.02f, 0.2f, el);
    // Cloud tops are lit, their bellies grey.
    vec3 cloud_col = mix(vec3(0.7f, 0.72f, 0.76f), vec3(1.0f), smoothstep(0.1f, 0.6f, puff));
    return mix(sky, cloud_col, cloud);
  }
  vec2 g = ground_point(d);
  float path = std::fabs(g.x * 0.8f + g.y * 0.3f + 0.3f * std::sin(g.y * 0.5f));
  if (path < 0.45f) {
    float wear = wt::gradient_noise(vec3(g.x * 5.0f, g.y * 5.0f, 3.0f));
    return vec3(0.6f, 0.58f, 0.55f) * (0.9f + 0.1f * wear);
  }
  float grass = wt::turbulence(vec3(g.x * 3.0f, g.y * 3.0f, 5.0f), 4);
  vec3 lawn = mix(vec3(0.2f, 0.42f, 0.12f), vec3(0.35f, 0.55f, 0.2f), std::min(grass, 1.0f));
  // Haze greys the lawn towards the horizon.
  return mix(lawn, vec3(0.55f, 0.6f, 0.55f), smoothstep(-0.15f, 0.0f, el) * 0.6f);
}

// Kitchen: cream walls, wooden cabinets above and below a dark counter, a
// window on one side, a checkered floor and a warm ceiling lamp.
vec3 kitchen(const vec3& d) {
  float el = elevation(d), az = azimuth(d);
  if (el > 0.95f) {
    vec3 lamp = glm::normalize(vec3(0.1f, 1.0f, 0.15f));
    return vec3(0.9f, 0.86f, 0.8f) * 0.8f + vec3(1.0f, 0.85f, 0.6f) * glow(d, lamp, 0.12f, 0.1f);
  }
  if (el < -0.42f) {
    vec2 g = ground_point(d);
    int parity = static_cast<int>(std::floor(g.x * 3.0f)) + static_cast<int>(std::floor(g.y * 3.0f));
    return (parity & 1) ? vec3(0.12f, 0.12f, 0.13f) : vec3(0.88f, 0.87f, 0.84f);
  }
  // The window: a range of azimuth with the outdoors behind it.
  bool in_window = std::fabs(az - 1.2f) < 0.45f && el > 0.08f && el < 0.6f;
  if (in_window) {
    float frame_u = std::fabs(az - 1.2f), frame_v = std::fabs(el - 0.34f);
    if (frame_u > 0.41f || frame_v > 0.22f || frame_u < 0.02f) return vec3(0.92f, 0.9f, 0.86f);
    return mix(vec3(0.55f, 0.75f, 0.5f), vec3(0.75f, 0.88f, 1.0f), smoothstep(0.15f, 0.45f, el));
  }
  // Cabinet doors: panels of fixed width in azimuth with dark gaps between.
  float door = fract(az * (16.0f / (2.0f * kPi)));
  float grain = wt::turbulence(vec3(az * 4.0f, el * 40.0f, 1.0f), 3);
  vec3 wood = mix(vec3(0.55f, 0.34f, 0.18f), vec3(0.42f, 0.25f, 0.12f), std::min(grain, 1.0f));
  bool upper = el > 0.3f && el < 0.8f;
  bool lower = el > -0.42f && el < -0.08f;
  if (upper || lower) {
    if (door < 0.04f) return vec3(0.12f, 0.08f, 0.05f);
    return lower ? wood * 1.15f : wood;
  }
  if (el >= -0.08f && el < 0.0f) {
    float speck = wt::gradient_noise(vec3(az * 60.0f, el * 60.0f, 2.0f));
    return vec3(0.16f, 0.15f, 0.15f) + vec3(0.08f) * std::max(speck, 0.0f);
  }
  // Tiled splashback just above the counter, plain wall elsewhere.
  if (el >= 0.0f && el < 0.3f) {
    float tx = fract(az * 24.0f), ty = fract(el * 24.0f);
    if (tx < 0.08f || ty < 0.08f) return vec3(0.7f, 0.7f, 0.68f);
    return vec3(0.55f, 0.7f, 0.72f);
  }
  return vec3(0.93f, 0.87f, 0.72f);
}

using Environment = vec3 (*)(const vec3&);

// A mirror ball photographed from far away along -z: the pixel at disc position
// (x, y) sees the ball's normal n = (x, y, sqrt(1 - x^2 - y^2)) and the
// environment in the reflected direction of the viewing ray (0, 0, -1). Outside
// the disc the image is black, as in a cropped probe photograph.
Image8 make_probe(Environment env, int size) {
  constexpr int kSub = 3;  // 3 x 3 samples per pixel smooth the disc's rim
  Image8 img(size, size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      vec3 sum(0.0f);
      for (int sy = 0; sy < kSub; ++sy)
        for (int sx = 0; sx < kSub; ++sx) {
          float px = (x + (sx + 0.5f) / kSub) / size * 2.0f - 1.0f;
          float py = 1.0f - (y + (sy + 0.5f) / kSub) / size * 2.0f;  // row 0 is the top
          float r2 = px * px + py * py;
          if (r2 >= 1.0f) continue;
          vec3 n(px, py, std::sqrt(1.0f - r2));
          vec3 view(0.0f, 0.0f, -1.0f);
          vec3 dir = view - 2.0f * glm::dot(view, n) * n;
          sum += env(glm::normalize(dir));
        }
      img.set(x, y, sum / float(kSub * kSub));
    }
  return img;
}

// Direction on the unit sphere for texel (u, v): the inverse of the renderer's
// spherical mapping u = 0.5 + atan2(n.z, n.x) / 2 pi, v = 0.5 - asin(n.y) / pi,
// so the map lands on a sphere with the poles at +-y.
vec3 sphere_dir(float u, float v) {
  float phi = (u - 0.5f) * 2.0f * kPi;
  float lat = (0.5f - v) * kPi;
  return vec3(std::cos(lat) * std::cos(phi), std::sin(lat), std::cos(lat) * std::sin(phi));
}

// Continents and oceans from 3D noise evaluated on the sphere itself, so the map
// has no seam at u = 0 and no pinching at the poles.
Image8 make_planet(int width, int height) {
  constexpr int kSub = 2;
  const int n = width * height * kSub * kSub;
  std::vector<float> relief(n);
  auto height_at = [](const vec3& p) {
    return fbm(p * 1.7f + vec3(11.0f, 3.0f, 7.0f), 7) + 0.25f * fbm(p * 0.6f + vec3(2.0f), 2);
  };
  auto sample_dir = [&](int i) {
    int s = i % (kSub * kSub), pix = i / (kSub * kSub);
    int x = pix % width, y = pix / width;
    float u = (x + (s % kSub + 0.5f) / kSub) / width;
    float v = (y + (s / kSub + 0.5f) / kSub) / height;
    return sphere_dir(u, v);
  };
  for (int i = 0; i < n; ++i) relief[i] = height_at(sample_dir(i));
  // Sea level as a quantile of the relief: about 30% land whatever the noise's range.
  std::vector<float> sorted(relief);
  std::nth_element(sorted.begin(), sorted.begin() + n * 7 / 10, sorted.end());
  const float sea = sorted[n * 7 / 10];
  // Mountains and snow are placed relative to the highest point.
  const float peak = *std::max_element(relief.begin(), relief.end());

  Image8 img(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      vec3 sum(0.0f);
      for (int s = 0; s < kSub * kSub; ++s) {
        int i = (y * width + x) * kSub * kSub + s;
        vec3 p = sample_dir(i);
        float h = relief[i] - sea;
        float lat = std::fabs(std::asin(p.y)) * (180.0f / kPi);
        vec3 c;
        if (h < 0.0f) {
          // Shallow shelves are lighter than the deep ocean.
          c = mix(vec3(0.09f, 0.3f, 0.45f), vec3(0.02f, 0.07f, 0.22f), smoothstep(0.0f, 0.25f, -h));
        } else {
          float e = h / (peak - sea);
          float moisture = wt::gradient_noise(p * 3.0f + vec3(5.0f, 1.0f, 9.0f));
          // Deserts in the dry subtropics, forest and grassland elsewhere.
          float dry = smoothstep(0.0f, -0.25f, moisture) * smoothstep(8.0f, 18.0f, lat) *
                      smoothstep(40.0f, 28.0f, lat);
          vec3 green = mix(vec3(0.12f, 0.35f, 0.1f), vec3(0.3f, 0.45f, 0.18f), 0.5f + moisture);
          c = mix(green, vec3(0.78f, 0.66f, 0.44f), dry);
          c = mix(c, vec3(0.42f, 0.33f, 0.24f), smoothstep(0.3f, 0.55f, e));
          c = mix(c, vec3(0.95f), smoothstep(0.62f, 0.75f, e));
          c = mix(c, vec3(0.55f, 0.55f, 0.45f), 0.7f * smoothstep(55.0f, 65.0f, lat));  // tundra
        }
        // Polar ice over land and sea, its edge ragged with noise.
        float ice_edge = 69.0f + 10.0f * fbm(p * 5.0f + vec3(1.0f, 8.0f, 2.0f), 4);
        c = mix(c, vec3(0.93f, 0.95f, 0.97f), smoothstep(ice_edge - 0.7f, ice_edge + 0.7f, lat));
        sum += c;
      }
      img.set(x, y, sum / float(kSub * kSub));
    }
  return img;
}

// The clear sky of sky_sun.hdr, in linear radiance: blue overhead, paler and
// brighter toward the horizon, a sun disc 1.5 degrees in radius at 30 degrees
// elevation with a glow around it, and dark ground below the horizon.
const vec3 kSunDirection = glm::normalize(vec3(0.45f, 0.48f, -0.75f));
constexpr float kSunRadius = 1.5f * kPi / 180.0f;
vec3 clear_sky(const vec3& d) {
  if (d.y < 0.0f) return vec3(0.12f, 0.1f, 0.08f);  // the ground
  const float toward_horizon = std::pow(1.0f - d.y, 4.0f);
  vec3 sky = mix(vec3(0.22f, 0.42f, 1.0f), vec3(1.1f, 1.2f, 1.3f), toward_horizon);
  const float angle = std::acos(std::min(1.0f, glm::dot(d, kSunDirection)));
  sky += vec3(4.0f, 3.4f, 2.6f) * std::exp(-angle / 0.08f);  // the glow
  if (angle < kSunRadius) sky += vec3(2000.0f, 1850.0f, 1600.0f);
  return sky;
}

// The sky on the renderer's latitude-longitude grid (u = atan2(x, -z) / 2 pi,
// v = acos(y) / pi; docs/scene-format.md), 4 x 4 samples a texel for the sun's rim.
std::vector<float> make_sky(int width, int height) {
  constexpr int kSub = 4;
  std::vector<float> rgb(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      vec3 sum(0.0f);
      for (int sy = 0; sy < kSub; ++sy)
        for (int sx = 0; sx < kSub; ++sx) {
          const float phi = 2.0f * kPi * (x + (sx + 0.5f) / kSub) / width;
          const float theta = kPi * (y + (sy + 0.5f) / kSub) / height;
          sum += clear_sky(vec3(std::sin(phi) * std::sin(theta), std::cos(theta), -std::cos(phi) * std::sin(theta)));
        }
      const vec3 c = sum / float(kSub * kSub);
      for (int k = 0; k < 3; ++k) rgb[3 * (static_cast<size_t>(y) * width + x) + k] = c[k];
    }
  return rgb;
}

bool write_hdr(const std::filesystem::path& path, int width, int height, const std::vector<float>& rgb) {
  if (!stbi_write_hdr(path.string().c_str(), width, height, 3, rgb.data())) {
    std::fprintf(stderr, "wavetrace-textures: cannot write %s\n", path.string().c_str());
    return false;
  }
  std::printf("%s (%d x %d)\n", path.string().c_str(), width, height);
  return true;
}

// The round bumps of bumps_normal.png and bumps_height.png, 256 x 256 texels:
// sixteen bumps in four rows of four, one every 64 texels, every other row shifted
// by half a bump, so that the images tile both ways. A bump of radius R = 26 texels
// has the height h(r) = H (1 - (r/R)^2)^2, H = 0.6 R: level at its top and at its
// rim, steepest (43 degrees) at R / sqrt(3). The bumps do not overlap. At (x, y) in
// texels (y down the rows): the height and its derivatives, analytically.
constexpr int kBumpsSize = 256, kBumpsPitch = 64;
constexpr double kBumpRadius = 26.0, kBumpHeight = 0.6 * kBumpRadius;

void bumps_at(double x, double y, double& h, double& gx, double& gy) {
  h = gx = gy = 0.0;
  for (int j = 0; j < kBumpsSize / kBumpsPitch; ++j) {
    for (int i = 0; i < kBumpsSize / kBumpsPitch; ++i) {
      const double cx = std::fmod((i + 0.5 + 0.5 * (j % 2)) * kBumpsPitch, kBumpsSize), cy = (j + 0.5) * kBumpsPitch;
      // The nearest copy of the bump on the torus.
      const double dx = std::fmod(x - cx + 1.5 * kBumpsSize, kBumpsSize) - 0.5 * kBumpsSize;
      const double dy = std::fmod(y - cy + 1.5 * kBumpsSize, kBumpsSize) - 0.5 * kBumpsSize;
      const double s = (dx * dx + dy * dy) / (kBumpRadius * kBumpRadius);
      if (s < 1.0) {
        h += kBumpHeight * (1.0 - s) * (1.0 - s);
        const double k = -4.0 * kBumpHeight * (1.0 - s) / (kBumpRadius * kBumpRadius);  // dh/dx = k dx
        gx += k * dx;
        gy += k * dy;
      }
    }
  }
}

// An image of the bumps, colour(h, dh/dx, dh/drow) at each texel's centre.
template <class Colour>
Image8 bumps_image(const Colour& colour) {
  Image8 img(kBumpsSize, kBumpsSize);
  for (int row = 0; row < kBumpsSize; ++row) {
    for (int col = 0; col < kBumpsSize; ++col) {
      double h, gx, gy;
      bumps_at(col + 0.5, row + 0.5, h, gx, gy);
      img.set(col, row, colour(h, gx, gy));
    }
  }
  return img;
}

// bumps_normal.png: the bumps as a tangent-space normal map, the normal n stored as
// n / 2 + 1/2 (flat is (128, 128, 255)), in the OpenGL and glTF convention
// wavetrace's normal_texture reads (docs/scene-format.md): +x (red) along +u, +y
// (green) up the image, +z (blue) out of the surface; read it with "colorspace":
// "linear". The normal (-dh/dx, dh/drow, 1), normalized, is evaluated analytically
// at each texel's centre, so nothing is sampled and nothing aliases.
Image8 make_bumps_normal() {
  return bumps_image([](double, double gx, double gy) {
    // Up the image is -row: n.y = dh/drow.
    const vec3 n = glm::normalize(vec3(static_cast<float>(-gx), static_cast<float>(gy), 1.0f));
    return 0.5f * n + vec3(0.5f);
  });
}

// bumps_height.png: the same bumps as heights, h / H at each texel's centre (grey,
// 8-bit, linear: read it with "colorspace": "linear"). As a bump map of a surface
// where a texel is w units wide, bump_scale H w (H = 15.6 texels) makes the bumps of
// the normal map.
Image8 make_bumps_height() {
  return bumps_image([](double h, double, double) { return vec3(static_cast<float>(h / kBumpHeight)); });
}

bool write_png(const std::filesystem::path& path, const Image8& img) {
  if (!stbi_write_png(path.string().c_str(), img.width, img.height, 3, img.rgb.data(), img.width * 3)) {
    std::fprintf(stderr, "wavetrace-textures: cannot write %s\n", path.string().c_str());
    return false;
  }
  std::printf("%s (%d x %d)\n", path.string().c_str(), img.width, img.height);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: wavetrace-textures OUTDIR\n");
    return 2;
  }
  const std::filesystem::path out = argv[1];
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "wavetrace-textures: cannot create %s: %s\n", out.string().c_str(),
                 ec.message().c_str());
    return 1;
  }
  // The files are committed: the strongest compression keeps the repository small.
  stbi_write_png_compression_level = 9;

  constexpr int kProbe = 256;
  struct {
    const char* file;
    Environment env;
  } probes[] = {{"probe_beach.png", beach},
                {"probe_building.png", building},
                {"probe_campus.png", campus},
                {"probe_kitchen.png", kitchen}};
  bool ok = true;
  for (const auto& p : probes) ok = write_png(out / p.file, make_probe(p.env, kProbe)) && ok;
  ok = write_png(out / "planet.png", make_planet(756, 378)) && ok;
  ok = write_png(out / "bumps_normal.png", make_bumps_normal()) && ok;
  ok = write_png(out / "bumps_height.png", make_bumps_height()) && ok;
  ok = write_hdr(out / "sky_sun.hdr", 512, 256, make_sky(512, 256)) && ok;
  return ok ? 0 : 1;
}
