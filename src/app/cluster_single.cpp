// The cluster of a build without MPI: always one process.
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "app/cluster.hpp"
#include "app/cluster_launch.hpp"

namespace wt::app {

bool built_with_mpi() { return false; }

Cluster start_cluster(int*, char***) {
  const int ranks = launched_ranks();
  if (ranks != 1) {
    throw std::runtime_error("this wavetrace was built without MPI (libopenmpi-dev was not found when it was "
                             "built), so it cannot run as one of " +
                             (ranks > 1 ? std::to_string(ranks) : std::string("several")) +
                             " MPI ranks: each would render the whole job alone");
  }
  return Cluster();
}

void end_cluster() {}

void abort_cluster(int code) { std::exit(code); }

}  // namespace wt::app
