// One render over the ranks of an MPI run (`mpirun -n N wavetrace render ...`): each
// rank renders a contiguous range of the samples on its host's devices, and rank 0
// sums the films in rank order and alone writes the image. Like the split over a
// host's devices (dispatch/split.hpp), the counter-based random numbers make the image
// the one-process image within float-summation rounding.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "app/cluster.hpp"
#include "app/job.hpp"
#include "render/passes.hpp"

namespace wt::app {

// Samples [first, first + count) over ranks in proportion to their weights (each > 0),
// each rank a contiguous range, in rank order; a rank may get none.
std::vector<SamplePass> rank_samples(int32_t first, int32_t count, const std::vector<double>& weights);

// The devices of `devices` that rank `local_rank` of the `local_ranks` ranks on one
// host renders on: every local_ranks-th, so that ranks share a host's GPUs out; with
// more ranks than devices, one each, ranks sharing.
std::vector<int> local_share(const std::vector<int>& devices, int local_rank, int local_ranks);

// What one rank says of its part of a render.
struct RankStatus {
  int rank = 0;
  std::string host;
  int exit_code = 0;
  std::string message;
};

// The one line that says which ranks failed and why: ranks failing alike share a clause
// ("ranks 1, 2 of 3 (node2, node3): scene.json: ...").
std::string describe_failures(const std::vector<RankStatus>& failed, int ranks);

// Collective, before the render: every rank's readiness (`out` failed or not), and on
// rank 0 the check that every rank renders the same (`signature`: the settings, kernel
// and scene's counts). Then each rank's share of the samples, in proportion to
// `weight` (its devices), set into `options`. Where any rank failed, every rank's
// `out` fails with the line that says which and why; returns whether all is well.
bool agree_on_samples(const Cluster& cluster, JobOutcome& out, RenderOptions& options, const std::string& signature,
                      double weight);

// Collective, after the render: every rank's outcome; where all rendered, rank 0's
// result becomes the whole render's (the film's sums over every sample, in rank
// order; rays, paths and each rank's share), the others' stay their own. Where any
// failed, every rank's `out` fails with the line that says which and why.
void combine_results(const Cluster& cluster, JobOutcome& out);

}  // namespace wt::app
