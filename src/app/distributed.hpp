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
#include "dispatch/renderer.hpp"
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
// `weights`, where given, gets every rank's weight (an adaptive render's ranks share
// each round's pixels by them).
bool agree_on_samples(const Cluster& cluster, JobOutcome& out, RenderOptions& options, const std::string& signature,
                      double weight, std::vector<double>* weights = nullptr);

// Collective: an adaptive render (render/adaptive.hpp) over the ranks. Rank 0 runs it,
// and before each round sends every rank the round (its samples, the pixels still
// going); each rank renders its run of those pixels (cut in proportion to
// `weights`) with `rounds` (its devices', dispatch/renderer.hpp's adaptive_rounds),
// and rank 0 adds the runs' sums (each pixel's from one rank alone: the image is the
// one-process image). Rank 0's result is the whole render's image; every rank's
// counts are its own. A rank whose round fails renders no more, adds zeros, and
// reports its error at the end (combine_results), as rank 0 does.
RenderResult render_adaptive_ranks(const Cluster& cluster, const ChunkRenderer& rounds, const RenderOptions& options,
                                   const std::vector<double>& weights, const AdaptiveHooks& hooks);

// Collective, after the render: every rank's outcome; where all rendered, rank 0's
// result becomes the whole render's (the film's sums over every sample, in rank
// order; rays, paths and each rank's share), the others' stay their own. Where any
// failed, every rank's `out` fails with the line that says which and why.
// Of an adaptive render (`adaptive`), rank 0's image is already the whole one and
// only the counts are combined.
void combine_results(const Cluster& cluster, JobOutcome& out, bool adaptive = false);

}  // namespace wt::app
