#include "app/progress.hpp"

#include <cstdio>

namespace wt::app {

namespace {
constexpr double kShowAfterSeconds = 1.0;
constexpr double kRedrawSeconds = 0.25;
}  // namespace

ProgressLine::~ProgressLine() {
  if (drawn_) std::fputc('\n', stderr);
}

ProgressFn ProgressLine::callback() {
  return [this](double done, uint64_t rays, double seconds) { update(done, rays, seconds); };
}

void ProgressLine::converged(uint64_t converged, uint64_t pixels) {
  converged_ = converged;
  pixels_ = pixels;
}

void ProgressLine::update(double done, uint64_t rays, double seconds) {
  if (seconds < kShowAfterSeconds || (seconds - last_draw_ < kRedrawSeconds && done < 1.0)) return;
  last_draw_ = seconds;
  drawn_ = true;
  const double left = done > 0 ? seconds * (1.0 - done) / done : 0.0;
  std::fprintf(stderr, "\r%12llu / %llu paths (%5.1f%%)  %8.2f M rays/s  %6.1f s left ",
               static_cast<unsigned long long>(done * total_paths_), static_cast<unsigned long long>(total_paths_),
               100.0 * done, seconds > 0 ? rays / seconds / 1e6 : 0.0, left);
  if (pixels_ > 0) {
    // An adaptive render's "left" is at most that: converged pixels take no more samples.
    std::fprintf(stderr, " %llu / %llu pixels converged ", static_cast<unsigned long long>(converged_),
                 static_cast<unsigned long long>(pixels_));
  }
  std::fflush(stderr);
}

}  // namespace wt::app
