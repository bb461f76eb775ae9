// Deliberate bugs for mutation testing. A build configured with
// -DWAVETRACE_MUTANTS=ON (a test-only build: scripts/mutants.sh and the sanitizer
// build) compiles each of them in behind a check of WT_MUTANT(Name), and the
// environment variable WAVETRACE_MUTANT chooses at most one at run time, so that one
// build serves every mutant. Every other build, the release build among them,
// defines WT_MUTANT(Name) as false: the bugs are not compiled at all. The mutants
// act on the CPU only (device code sees false); the table of which tests kill each
// one is in docs/testing.md.
#pragma once

#include "wavetrace/config.hpp"

#if defined(WT_MUTANTS) && !defined(__CUDA_ARCH__)
#include <cstdio>
#include <cstdlib>
#include <cstring>
#endif

namespace wt {

// Each mutant with the name WAVETRACE_MUTANT gives it.
#define WT_MUTANT_LIST(X)                                                                   \
  X(LightPdfScaled, "light-pdf-1.05")             /* an emitter's density, drawn and evaluated */ \
  X(BsdfPdfScaled, "bsdf-pdf-1.05")               /* the density light sampling takes a BSDF's */ \
  X(MissingCosine, "missing-cosine")              /* the receiver's cosine in a light sample */  \
  X(MisWeightsSwapped, "mis-weights-swapped")     /* each strategy weighted with the other's */  \
  X(DimensionReused, "dimension-reused")          /* the light's pick and its point share one */ \
  X(TextureVFlipped, "texture-v-flipped")         /* image textures on surfaces */               \
  X(RouletteWithoutOneOverQ, "roulette-without-1/q")                                           \
  X(EnvironmentRowShifted, "environment-row-shifted") /* sampled one row off its density */      \
  X(ShadowIgnoresFirstHit, "shadow-ignores-first-hit")                                        \
  X(VisibleNormalsWithoutG1, "visible-normals-without-g1") /* GGX's density of visible normals */ \
  X(GlassUnscaledRadiance, "glass-unscaled-radiance") /* rough transmission without 1 / eta^2 */ \
  X(CompensationDropped, "compensation-dropped")  /* conductors' multiple-scattering lobe */ \
  X(BlendWeightSwapped, "blend-weight-swapped")   /* a blend's pick takes the first for the second */

enum class Mutant : int {
  None,
#define WT_MUTANT_ENUM(name, text) name,
  WT_MUTANT_LIST(WT_MUTANT_ENUM)
#undef WT_MUTANT_ENUM
};

#if defined(WT_MUTANTS)
#if !defined(__CUDA_ARCH__)
// The mutant WAVETRACE_MUTANT names (read once); an unknown name stops the process,
// so that a misspelt mutant never passes for a killed one's survivor.
inline Mutant active_mutant() {
  static const Mutant active = [] {
    const char* name = std::getenv("WAVETRACE_MUTANT");
    if (name == nullptr || *name == '\0') return Mutant::None;
#define WT_MUTANT_PARSE(id, text) \
  if (std::strcmp(name, text) == 0) return Mutant::id;
    WT_MUTANT_LIST(WT_MUTANT_PARSE)
#undef WT_MUTANT_PARSE
    std::fprintf(stderr, "WAVETRACE_MUTANT: unknown mutant '%s'\n", name);
    std::exit(2);
  }();
  return active;
}
#endif
WT_HD inline bool mutant_on(Mutant m) {
#if defined(__CUDA_ARCH__)
  (void)m;
  return false;
#else
  return active_mutant() == m;
#endif
}
#define WT_MUTANT(name) (::wt::mutant_on(::wt::Mutant::name))
#else
#define WT_MUTANT(name) false
#endif

}  // namespace wt
