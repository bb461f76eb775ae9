// The fuzz build's host-only library leaves out the renderer (CUDA, compiled by
// nvcc), and with it run_job, which only run_batch calls; no target calls that.
// This definition satisfies the linker and stops loudly if that ever changes.
#include <cstdio>
#include <cstdlib>

#include "app/job.hpp"

namespace wt::app {

JobOutcome run_job(const Job&) {
  std::fprintf(stderr, "wavetrace fuzz: run_job is not part of the fuzz build\n");
  std::abort();
}

}  // namespace wt::app
