// Named presets for the `conductor` material: the complex index of refraction
// eta + i k of a metal, one value per RGB channel. The R, G and B channels stand for
// the vacuum wavelengths 630, 532 and 465 nm. Every number comes from a published
// measured table (the source of each metal is cited on its line); where the table has
// no point at one of those wavelengths, the value is a linear interpolation in
// wavelength between the two tabulated points either side of it. The method, the
// normal-incidence reflectance of each preset and the full citations are in
// docs/conductor-data.md.
#pragma once

#include "wavetrace/config.hpp"

namespace wt {

struct ConductorPreset {
  const char* name;  // lowercase ASCII
  vec3 eta;          // real part of the index of refraction, (R, G, B)
  vec3 k;            // extinction coefficient, (R, G, B)
};

inline constexpr ConductorPreset kConductorPresets[] = {
    // P. B. Johnson and R. W. Christy, Phys. Rev. B 6, 4370 (1972).
    {"gold", vec3(0.188f, 0.544f, 1.332f), vec3(3.403f, 2.231f, 1.869f)},
    // P. B. Johnson and R. W. Christy, Phys. Rev. B 6, 4370 (1972).
    {"silver", vec3(0.057f, 0.054f, 0.047f), vec3(4.254f, 3.429f, 2.803f)},
    // P. B. Johnson and R. W. Christy, Phys. Rev. B 6, 4370 (1972).
    {"copper", vec3(0.275f, 1.116f, 1.247f), vec3(3.373f, 2.596f, 2.456f)},
    // A. D. Rakic, Appl. Opt. 34, 4755 (1995).
    {"aluminium", vec3(1.430f, 0.939f, 0.686f), vec3(7.508f, 6.420f, 5.635f)},
    // P. B. Johnson and R. W. Christy, Phys. Rev. B 9, 5056 (1974).
    {"iron", vec3(2.892f, 2.895f, 2.646f), vec3(3.065f, 2.918f, 2.805f)},
    // P. B. Johnson and R. W. Christy, Phys. Rev. B 9, 5056 (1974).
    {"chromium", vec3(3.145f, 3.034f, 2.456f), vec3(3.312f, 3.330f, 3.210f)},
    // P. B. Johnson and R. W. Christy, Phys. Rev. B 9, 5056 (1974).
    {"titanium", vec3(2.698f, 2.479f, 2.305f), vec3(3.757f, 3.351f, 3.082f)},
    // P. B. Johnson and R. W. Christy, Phys. Rev. B 9, 5056 (1974).
    {"nickel", vec3(1.990f, 1.877f, 1.765f), vec3(4.094f, 3.495f, 3.048f)},
    // A. Tselin et al., Phys. Rev. B 110, 195130 (2024): ellipsometry of an 80 nm film.
    {"platinum", vec3(2.168f, 1.877f, 1.696f), vec3(5.059f, 4.370f, 3.874f)},
};

}  // namespace wt
