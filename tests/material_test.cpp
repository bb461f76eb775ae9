// Sampling the BSDF (bsdf.hpp) for every study material kind at fixed hits, and shade_hit's Russian
// roulette, against what each material promises: the hemisphere a diffuse bounce
// goes to, the mirror law, Fresnel (Schlick) frequencies, Snell's law, where the
// spawned ray starts, and that roulette leaves the expected throughput unchanged.
//
// Statistical thresholds: frequencies are compared with their probability p over N
// independent Rng keys, rejecting beyond 5.5 binomial standard deviations
// sqrt(p (1 - p) / N): a correct material fails with probability 3.8e-8 per check
// (normal approximation; N p >= 2000 in every check here). Keys are fixed, so
// results are reproducible.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "wavetrace/path.hpp"

namespace wt {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// A sampled frequency's tolerance: 4 binomial standard deviations (two-sided 6.3e-5
// for each check; the seeds are fixed).
double binomial_bound(double p, int n) { return 4.0 * std::sqrt(p * (1.0 - p) / n); }

Material make_material(MaterialKind kind, vec3 albedo, float fuzz = 0.0f, float ior = 1.5f, int texture = -1) {
  Material m{};
  m.kind = kind;
  m.texture = texture;
  m.fuzz = fuzz;
  m.ior = ior;
  m.albedo = albedo;
  m.emission = vec3(0.0f);
  m.sort_key = 0;
  return m;
}

// One scattering event through the BSDF contract: false where the path ends.
bool scatter(const Material& m, const Texture* textures, const ImageView* images, const Ray& in,
             const SurfacePoint& sp, const Rng& rng, vec3& attenuation, Ray& next) {
  if (m.kind == MaterialKind::Emissive) return false;
  const BsdfAt b = bsdf_at(m, BsdfInputs{}, sp, material_albedo(m, textures, images, sp), -in.dir);
  const BsdfSample s = sample_bsdf(b, -in.dir, rng);
  if (s.lobe == 0u) return false;
  attenuation = s.weight;
  next = spawn_ray(sp, s.wi);
  return true;
}

// A hit on the top of a unit sphere centred at the origin: p = (0, 1, 0), n = +y.
SurfacePoint top_hit(bool front) {
  SurfacePoint sp;
  sp.p = vec3(0.0f, 1.0f, 0.0f);
  sp.n = vec3(0.0f, 1.0f, 0.0f);
  sp.ng = sp.n;
  sp.local = sp.p;
  sp.uv = vec2(0.0f);
  sp.dpdu = vec3(1.0f, 0.0f, 0.0f);
  sp.has_uv = false;
  sp.front = front;
  sp.offset = kSphereSurfaceOffset;
  return sp;
}

// A direction in the x-y plane at `deg` from the vertical, going down (towards -y)
// when `down`, else up.
vec3 at_angle(double deg, bool down) {
  return vec3(float(std::sin(deg * kDegToRad)), float((down ? -1.0 : 1.0) * std::cos(deg * kDegToRad)), 0.0f);
}

// The outgoing ray must start the surface's offset from the hit along the normal,
// on the side the ray goes to.
void expect_spawned_on_its_side(const SurfacePoint& sp, const Ray& next) {
  float side = glm::dot(next.dir, sp.n) >= 0.0f ? 1.0f : -1.0f;
  vec3 want = sp.p + side * sp.offset * sp.n;
  EXPECT_NEAR(glm::length(next.origin - want), 0.0f, 1e-7f);
}

TEST(Material, LambertianScattersCosineDistributedIntoTheFacingHemisphere) {
  // From outside (front) the bounce leaves above the surface; from inside it stays
  // inside. E[cos theta] about the facing normal is 2/3 for the cosine density
  // (1/2 for a uniform hemisphere); var(cos) = 1/18, so 20000 samples give sd 1.7e-3
  // and the 6-sd bound (tail 2e-9) is 0.01.
  const Material m = make_material(MaterialKind::Lambertian, vec3(0.2f, 0.4f, 0.6f));
  for (bool front : {true, false}) {
    SurfacePoint sp = top_hit(front);
    Ray in{sp.p - at_angle(30.0, front), at_angle(30.0, front)};
    double sum_cos = 0.0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      Rng rng = Rng::at(1, uint32_t(i), 0, 0);
      vec3 att;
      Ray next;
      ASSERT_TRUE(scatter(m, nullptr, nullptr, in, sp, rng, att, next));
      EXPECT_EQ(att, m.albedo);
      EXPECT_NEAR(glm::length(next.dir), 1.0f, 1e-5f);
      float c = glm::dot(next.dir, front ? sp.n : -sp.n);
      ASSERT_GE(c, 0.0f) << "front=" << front << " sample " << i;
      sum_cos += c;
      expect_spawned_on_its_side(sp, next);
    }
    EXPECT_NEAR(sum_cos / n, 2.0 / 3.0, 0.01) << "front=" << front;
  }
}

TEST(Material, TexturedAlbedoIsAlbedoTimesTexture) {
  Texture checker = image_texture(-1, Wrap::Repeat, Wrap::Clamp);
  checker.kind = TextureKind::Checker;
  checker.scale = 1.0f;
  checker.a = vec3(0.9f, 0.8f, 0.7f);
  checker.b = vec3(0.1f, 0.2f, 0.3f);
  const Texture tex[] = {checker};
  for (MaterialKind kind : {MaterialKind::Lambertian, MaterialKind::Metal}) {
    const Material m = make_material(kind, vec3(0.5f, 1.0f, 0.25f), 0.0f, 1.5f, 0);
    SurfacePoint sp = top_hit(true);
    Ray in{sp.p + vec3(0, 1, 0), vec3(0, -1, 0)};
    Rng rng = Rng::at(1, 2, 3, 4);
    vec3 att;
    Ray next;
    // local (0.5, 1, 0.5): floor 0 + 0, the even colour.
    sp.local = vec3(0.5f, 1.0f, 0.5f);
    ASSERT_TRUE(scatter(m, tex, nullptr, in, sp, rng, att, next));
    EXPECT_EQ(att, vec3(0.5f * 0.9f, 1.0f * 0.8f, 0.25f * 0.7f));
    // local (-0.5, 1, 0.5): floor -1 + 0, the odd colour.
    sp.local = vec3(-0.5f, 1.0f, 0.5f);
    ASSERT_TRUE(scatter(m, tex, nullptr, in, sp, rng, att, next));
    EXPECT_EQ(att, vec3(0.5f * 0.1f, 1.0f * 0.2f, 0.25f * 0.3f));
  }
}

TEST(Material, SmoothMetalReflectsExactlyAboutTheNormal) {
  const Material m = make_material(MaterialKind::Metal, vec3(0.9f, 0.8f, 0.7f), 0.0f);
  for (bool front : {true, false}) {
    for (double deg : {0.0, 20.0, 45.0, 80.0}) {
      SurfacePoint sp = top_hit(front);
      vec3 d = at_angle(deg, front);
      d.z = 0.3f;  // off the x-y plane too
      d = glm::normalize(d);
      Ray in{sp.p - d, d};
      vec3 att;
      Ray next;
      ASSERT_TRUE(scatter(m, nullptr, nullptr, in, sp, Rng::at(1, 0, 0, 0), att, next));
      // Mirror about the plane y = 0: only the y component flips.
      EXPECT_NEAR(next.dir.x, d.x, 1e-7f);
      EXPECT_NEAR(next.dir.y, -d.y, 1e-7f);
      EXPECT_NEAR(next.dir.z, d.z, 1e-7f);
      EXPECT_EQ(att, m.albedo);
      expect_spawned_on_its_side(sp, next);
      // It stays on the side it came from.
      EXPECT_EQ(next.origin.y > sp.p.y, front);
    }
  }
}

TEST(Material, FuzzyMetalStaysWithinFuzzOfTheMirrorOrIsAbsorbed) {
  // d = mirror + fuzz * s for uniform unit s. The normalised direction is within
  // asin(fuzz) of the mirror; it is absorbed exactly when d points into the surface,
  // which for a mirror at elevation a has probability (1 - sin(a) / fuzz) / 2
  // (z of a uniform sphere point is uniform on [-1, 1]) and is impossible at normal
  // incidence with fuzz < 1.
  const float fuzz = 0.5f;
  const Material m = make_material(MaterialKind::Metal, vec3(0.8f), fuzz);
  const double max_angle = std::asin(double(fuzz));
  struct Case {
    double incidence_deg;  // from the normal
    double p_absorb;
  };
  const double elev10 = std::sin(10.0 * kDegToRad);
  for (Case cs : {Case{0.0, 0.0}, Case{80.0, 0.5 * (1.0 - elev10 / fuzz)}}) {
    SurfacePoint sp = top_hit(true);
    vec3 d = at_angle(cs.incidence_deg, true);
    Ray in{sp.p - d, d};
    const vec3 mirror(d.x, -d.y, d.z);
    const int n = 100000;
    int absorbed = 0;
    for (int i = 0; i < n; ++i) {
      vec3 att;
      Ray next;
      if (!scatter(m, nullptr, nullptr, in, sp, Rng::at(8, uint32_t(i), 0, 0), att, next)) {
        ++absorbed;
        continue;
      }
      ASSERT_GT(glm::dot(next.dir, sp.n), 0.0f) << i;
      EXPECT_NEAR(glm::length(next.dir), 1.0f, 1e-5f);
      double ang = std::acos(std::fmin(1.0, double(glm::dot(next.dir, mirror))));
      ASSERT_LE(ang, max_angle + 1e-4) << i;
      expect_spawned_on_its_side(sp, next);
    }
    if (cs.p_absorb == 0.0) {
      EXPECT_EQ(absorbed, 0);
    } else {
      EXPECT_NEAR(double(absorbed) / n, cs.p_absorb, binomial_bound(cs.p_absorb, n)) << cs.incidence_deg;
    }
  }
}

TEST(Material, DielectricFromInsideBeyondCriticalAngleAlwaysReflects) {
  // Glass (ior 1.5) to air: critical angle 41.8 degrees; at 50 and 70 degrees every
  // key must reflect back inside.
  const Material m = make_material(MaterialKind::Dielectric, vec3(0.95f, 1.0f, 0.9f), 0.0f, 1.5f);
  for (double deg : {50.0, 70.0}) {
    SurfacePoint sp = top_hit(false);
    vec3 d = at_angle(deg, false);  // going up, out through the top
    Ray in{sp.p - d, d};
    for (int i = 0; i < 20000; ++i) {
      vec3 att;
      Ray next;
      ASSERT_TRUE(scatter(m, nullptr, nullptr, in, sp, Rng::at(4, uint32_t(i), 0, 0), att, next));
      ASSERT_NEAR(next.dir.x, d.x, 1e-6f) << i;
      ASSERT_NEAR(next.dir.y, -d.y, 1e-6f) << i;
      ASSERT_LT(next.origin.y, sp.p.y) << "reflected ray must start inside";
      EXPECT_EQ(att, m.albedo);
    }
  }
}

TEST(Material, DielectricReflectsWithSchlickFrequencyAndRefractsBySnell) {
  // Reflect frequency against Schlick's reflectance (r0 = 0.04 for ior 1.5):
  // from outside at normal incidence 0.04, at 60 degrees 0.04 + 0.96 / 32 = 0.07;
  // from inside at 30 degrees (below critical) 0.04 + 0.96 (1 - cos 30)^5.
  // Refracted rays obey sin(t) = eta sin(i) and continue through the surface.
  const Material m = make_material(MaterialKind::Dielectric, vec3(1.0f), 0.0f, 1.5f);
  struct Case {
    double deg;
    bool front;
  };
  for (Case cs : {Case{0.0, true}, Case{60.0, true}, Case{30.0, false}}) {
    const double eta = cs.front ? 1.0 / 1.5 : 1.5;
    const double cos_i = std::cos(cs.deg * kDegToRad);
    const double p_reflect = 0.04 + 0.96 * std::pow(1.0 - cos_i, 5.0);
    SurfacePoint sp = top_hit(cs.front);
    vec3 d = at_angle(cs.deg, cs.front);
    Ray in{sp.p - d, d};
    const int n = 200000;
    int reflected = 0;
    for (int i = 0; i < n; ++i) {
      vec3 att;
      Ray next;
      ASSERT_TRUE(scatter(m, nullptr, nullptr, in, sp, Rng::at(6, uint32_t(i), 1, 2), att, next));
      expect_spawned_on_its_side(sp, next);
      // Did it stay on the incoming side (reflection) or cross (refraction)?
      bool same_side = (next.dir.y > 0.0f) == cs.front;
      if (same_side) {
        ++reflected;
        ASSERT_NEAR(next.dir.y, -d.y, 1e-6f);
        ASSERT_NEAR(next.dir.x, d.x, 1e-6f);
      } else {
        double sin_t = std::sqrt(double(next.dir.x) * next.dir.x + double(next.dir.z) * next.dir.z);
        ASSERT_NEAR(sin_t, eta * std::sin(cs.deg * kDegToRad), 2e-6) << cs.deg;
        ASSERT_GE(next.dir.x, 0.0f);  // bends towards the normal, keeps going forwards
        ASSERT_NEAR(glm::length(next.dir), 1.0f, 1e-6f);
      }
    }
    EXPECT_NEAR(double(reflected) / n, p_reflect, binomial_bound(p_reflect, n)) << cs.deg << " front=" << cs.front;
  }
}

TEST(Material, CoatedReflectsWithSchlickFrequencyAtItsIor) {
  // The coat reflects (white, mirror direction) with Schlick's reflectance at its
  // ior; otherwise the base scatters diffusely with its albedo. ior 2.0: r0 = 1/9.
  const vec3 base(0.8f, 0.1f, 0.1f);
  const Material m = make_material(MaterialKind::Coated, base, 0.0f, 2.0f);
  for (double deg : {0.0, 60.0}) {
    const double r0 = 1.0 / 9.0;
    const double p_reflect = r0 + (1.0 - r0) * std::pow(1.0 - std::cos(deg * kDegToRad), 5.0);
    SurfacePoint sp = top_hit(true);
    vec3 d = at_angle(deg, true);
    Ray in{sp.p - d, d};
    const int n = 200000;
    int coat = 0;
    for (int i = 0; i < n; ++i) {
      vec3 att;
      Ray next;
      ASSERT_TRUE(scatter(m, nullptr, nullptr, in, sp, Rng::at(12, uint32_t(i), 0, 1), att, next));
      ASSERT_GE(glm::dot(next.dir, sp.n), 0.0f);
      expect_spawned_on_its_side(sp, next);
      if (att == vec3(1.0f)) {
        ++coat;
        ASSERT_NEAR(next.dir.x, d.x, 1e-6f);
        ASSERT_NEAR(next.dir.y, -d.y, 1e-6f);
      } else {
        ASSERT_EQ(att, base);
      }
    }
    EXPECT_NEAR(double(coat) / n, p_reflect, binomial_bound(p_reflect, n)) << deg;
  }
  // From inside the coat plays no part: always the base, scattering inwards.
  SurfacePoint sp = top_hit(false);
  Ray in{sp.p - vec3(0, 1, 0), vec3(0, 1, 0)};
  for (int i = 0; i < 5000; ++i) {
    vec3 att;
    Ray next;
    ASSERT_TRUE(scatter(m, nullptr, nullptr, in, sp, Rng::at(12, uint32_t(i), 0, 1), att, next));
    ASSERT_EQ(att, base);
    ASSERT_LE(glm::dot(next.dir, sp.n), 0.0f);
  }
}

TEST(Material, EmissiveDoesNotScatter) {
  Material m = make_material(MaterialKind::Emissive, vec3(1.0f));
  m.emission = vec3(4.0f, 3.0f, 2.0f);
  SurfacePoint sp = top_hit(true);
  Ray in{sp.p + vec3(0, 1, 0), vec3(0, -1, 0)};
  vec3 att(-1.0f);
  Ray next{vec3(-7.0f), vec3(-7.0f)};
  EXPECT_FALSE(scatter(m, nullptr, nullptr, in, sp, Rng::at(1, 1, 1, 1), att, next));
}

TEST(Material, SpawnRayOffsetsAlongTheGeometricNormalToTheOutgoingSide) {
  SurfacePoint sp = top_hit(true);
  sp.p = vec3(1.0f, 2.0f, 3.0f);
  sp.ng = glm::normalize(vec3(1.0f, 1.0f, 0.0f));
  sp.n = vec3(0.0f, 1.0f, 0.0f);  // the shading normal does not place the ray
  sp.offset = 0.25f;
  Ray out = spawn_ray(sp, glm::normalize(vec3(1.0f, 0.2f, 0.0f)));
  EXPECT_NEAR(glm::length(out.origin - (sp.p + 0.25f * sp.ng)), 0.0f, 1e-7f);
  Ray in = spawn_ray(sp, glm::normalize(vec3(-1.0f, 0.2f, 0.3f)));
  EXPECT_NEAR(glm::length(in.origin - (sp.p - 0.25f * sp.ng)), 0.0f, 1e-7f);
  EXPECT_EQ(in.dir, glm::normalize(vec3(-1.0f, 0.2f, 0.3f)));
}

// A one-sphere scene on host arrays for shade_hit.
struct OneSphereScene {
  SphereGeom sphere{0.0f, 0.0f, 0.0f, 1.0f};
  uint32_t sphere_material = 0;
  Instance instance{kIdentityTransform, kIdentityTransform, 0, PrimitiveKind::Sphere, -1, 1u};
  Material material;
  SceneView view{};
  explicit OneSphereScene(const Material& m) : material(m) {
    view.instances = &instance;
    view.spheres = &sphere;
    view.sphere_materials = &sphere_material;
    view.nodes = nullptr;  // shade_hit does not traverse
    view.materials = &material;
    view.textures = nullptr;
    view.images = nullptr;
    view.node_total = 0;
    view.sky = Sky{SkyKind::Uniform, vec3(0.0f), vec3(0.0f)};
  }
};

RenderParams params(int roulette_depth) { return RenderParams{64, 64, 1, 8, roulette_depth, 77}; }

// shade_hit after a camera ray (no BSDF density to weigh emission against); the
// scenes here have no emitter table, so no light is sampled.
bool shade(const SceneView& view, const RenderParams& rp, const Hit& hit, uint32_t pixel, uint32_t sample,
           uint32_t bounce, Ray& ray, vec3& throughput, vec3& radiance) {
  float pdf = 0.0f;
  ShadowRay shadow;
  const bool alive = shade_hit(view, rp, hit, pixel, sample, bounce, ray, throughput, radiance, pdf, shadow);
  EXPECT_FALSE(shadow.valid);
  return alive;
}

TEST(Material, ShadeHitEmitterAddsWeightedEmissionAndEnds) {
  Material m = make_material(MaterialKind::Emissive, vec3(0.0f));
  m.emission = vec3(4.0f, 2.0f, 1.0f);
  OneSphereScene scene(m);
  Ray ray{vec3(0.0f, 0.0f, 5.0f), vec3(0.0f, 0.0f, -1.0f)};
  vec3 throughput(0.5f, 0.25f, 1.0f), radiance(0.1f, 0.0f, 0.0f);
  EXPECT_FALSE(shade(scene.view, params(100), Hit{4.0f, 0, 0, 0.0f, 0.0f}, 0, 0, 0, ray, throughput, radiance));
  EXPECT_EQ(radiance, vec3(0.1f + 2.0f, 0.5f, 1.0f));
}

TEST(Material, ShadeHitRussianRouletteIsUnbiased) {
  // Ray down the z axis onto a unit Lambertian sphere at the origin (hit at t = 4).
  // Without roulette the throughput becomes throughput * albedo exactly. With
  // roulette from the first bounce (roulette_depth 0) a path survives with
  // p = min(max component, 0.95) and is divided by p, so over many keys
  // mean(survived ? throughput : 0) equals the no-roulette throughput. Per key the
  // result is T / p with probability p, else 0: var = T^2 (1 - p) / p, and the mean
  // of N keys is held to 5.5 sd (two-sided tail 3.8e-8 per component).
  struct Case {
    vec3 throughput_in;
    vec3 albedo;
  };
  for (Case cs : {Case{vec3(0.5f, 0.3f, 0.2f), vec3(0.6f)},          // p = 0.3
                  Case{vec3(1.0f), vec3(0.9f, 0.5f, 0.1f)},          // p = 0.9
                  Case{vec3(3.0f, 1.0f, 0.5f), vec3(0.7f, 0.7f, 0.7f)}}) {  // p capped at 0.95
    OneSphereScene scene(make_material(MaterialKind::Lambertian, cs.albedo));
    const Ray start{vec3(0.0f, 0.0f, 5.0f), vec3(0.0f, 0.0f, -1.0f)};
    const Hit hit{4.0f, 0, 0, 0.0f, 0.0f};

    vec3 expected = cs.throughput_in;
    {
      Ray ray = start;
      vec3 radiance(0.0f);
      ASSERT_TRUE(shade(scene.view, params(100), hit, 0, 0, 0, ray, expected, radiance));
      EXPECT_EQ(expected, cs.throughput_in * cs.albedo);
      EXPECT_EQ(radiance, vec3(0.0f));
      EXPECT_GT(ray.dir.z, 0.0f);  // scattered back up, off the top of the sphere
    }
    const double p = std::fmin(std::fmax(expected.x, std::fmax(expected.y, expected.z)), 0.95);

    const int n = 400000;
    double sum[3] = {0, 0, 0};
    int survived = 0;
    for (int i = 0; i < n; ++i) {
      Ray ray = start;
      vec3 t = cs.throughput_in, radiance(0.0f);
      if (shade(scene.view, params(0), hit, uint32_t(i), 0, 0, ray, t, radiance)) {
        ++survived;
        for (int k = 0; k < 3; ++k) sum[k] += t[k];
        // A survivor carries exactly T / p.
        ASSERT_NEAR(t.x, expected.x / p, 1e-5 * expected.x / p);
      }
    }
    for (int k = 0; k < 3; ++k) {
      double T = expected[k];
      double sd = T * std::sqrt((1.0 - p) / p / n);
      EXPECT_NEAR(sum[k] / n, T, 5.5 * sd + 1e-7) << "component " << k << " p=" << p;
    }
    EXPECT_NEAR(double(survived) / n, p, binomial_bound(p, n)) << "p=" << p;
  }
}

TEST(Material, ShadeHitWithoutRouletteNeverEndsADiffusePath) {
  // roulette_depth beyond the bounce: every key survives with throughput * albedo.
  OneSphereScene scene(make_material(MaterialKind::Lambertian, vec3(0.05f)));
  for (int i = 0; i < 10000; ++i) {
    Ray ray{vec3(0.0f, 0.0f, 5.0f), vec3(0.0f, 0.0f, -1.0f)};
    vec3 t(1.0f), radiance(0.0f);
    ASSERT_TRUE(shade(scene.view, params(8), Hit{4.0f, 0, 0, 0.0f, 0.0f}, uint32_t(i), 0, 3, ray, t, radiance));
    ASSERT_EQ(t, vec3(0.05f));
  }
}

}  // namespace
}  // namespace wt
