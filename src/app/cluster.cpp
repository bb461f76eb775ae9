#include "app/cluster.hpp"

#include <cstdlib>
#include <stdexcept>

#include "app/cluster_launch.hpp"

namespace wt::app {

std::string Cluster::name(int rank) const {
  std::string s = "rank " + std::to_string(rank) + " of " + std::to_string(ranks_);
  return s;
}

std::vector<std::string> Cluster::gather(const std::string& mine) const {
  if (!transport_) return {mine};
  return transport_->gather(mine);
}

std::string Cluster::broadcast(const std::string& from_root) const {
  return transport_ ? transport_->broadcast(from_root) : from_root;
}

void Cluster::sum_to_root(std::vector<float>& values) const {
  if (transport_) transport_->sum_to_root(values);
}

void Cluster::send(int to, int tag, const std::string& text) const {
  if (!transport_) throw std::logic_error("a cluster of one sends nothing");
  transport_->send(to, tag, text);
}

std::string Cluster::receive(int from, int tag) const {
  if (!transport_) throw std::logic_error("a cluster of one receives nothing");
  return transport_->receive(from, tag);
}

ClusterMessage Cluster::receive_any() const {
  if (!transport_) throw std::logic_error("a cluster of one receives nothing");
  return transport_->receive_any();
}

int launched_ranks() {
  if (const char* single = std::getenv(kSingleProcessVariable); single && *single) return 1;
  // Open MPI's mpirun, MPICH's and Intel's (PMI), Slurm's srun.
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "SLURM_STEP_NUM_TASKS"}) {
    if (const char* v = std::getenv(name); v && *v) {
      char* end = nullptr;
      const long n = std::strtol(v, &end, 10);
      if (end != v && n > 0) return static_cast<int>(n);
    }
  }
  // Launched by PMIx without a size in the environment: a rank, of how many MPI says.
  if (const char* v = std::getenv("PMIX_RANK"); v && *v) return 0;
  return 1;
}

}  // namespace wt::app
