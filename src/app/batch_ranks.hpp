// A batch over the ranks of an MPI run: rank 0 hands the jobs out to every rank's
// lanes as they free up (serve_ranks), each other rank's lane asks for jobs and says
// how each went (rank_lane). Internal to the batch.
#pragma once

#include <cstddef>
#include <string>

#include "app/batch_run.hpp"
#include "app/cluster.hpp"

namespace wt::app {

// Rank 0, on its main thread while its own lanes run: answers the other ranks' lanes,
// each asking for a job with what its last one did, until every one has been told
// that none is left.
void serve_ranks(const Cluster& cluster, BatchRun& batch, size_t remote_lanes);

// A lane of another rank than 0: asks rank 0 for jobs (its tag: the lane's number),
// runs each with `run` on the lane's devices, and says how it went.
void rank_lane(const Cluster& cluster, int tag, const std::string& devices, bool quiet, const JobRunner& run,
               const LaneDone& done);

}  // namespace wt::app
