// The ranks of a run started by an MPI launcher (`mpirun -n N wavetrace ...`, Slurm's
// srun): which one this process is, and the few exchanges the render and the batch
// make between them (docs/cli.md, "Several hosts"). A process that no MPI launcher
// started is a cluster of one, and never touches MPI; a build without MPI
// (libopenmpi-dev absent when it was built) is one always, and refuses to run as one
// rank of several.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace wt::app {

// The environment variable a batch sets for its job processes: each renders alone,
// even when the batch is a rank of an MPI run (whose variables they inherit).
constexpr const char* kSingleProcessVariable = "WAVETRACE_SINGLE_PROCESS";

// A message of one rank to another (the batch's job requests and their answers).
struct ClusterMessage {
  int from = 0;
  int tag = 0;
  std::string text;
};

class Cluster {
 public:
  // Every exchange below is collective unless it says otherwise: every rank calls it,
  // in the same order.
  class Transport {
   public:
    virtual ~Transport() = default;
    virtual std::vector<std::string> gather(const std::string& mine) = 0;
    virtual std::string broadcast(const std::string& from_root) = 0;
    virtual void sum_to_root(std::vector<float>& values) = 0;
    virtual void send(int to, int tag, const std::string& text) = 0;
    virtual std::string receive(int from, int tag) = 0;
    virtual ClusterMessage receive_any() = 0;
  };

  Cluster() = default;  // one process
  Cluster(int rank, int ranks, int local_rank, int local_ranks, std::string host, std::shared_ptr<Transport> t)
      : rank_(rank), ranks_(ranks), local_rank_(local_rank), local_ranks_(local_ranks), host_(std::move(host)),
        transport_(std::move(t)) {}

  int rank() const { return rank_; }
  int ranks() const { return ranks_; }
  bool root() const { return rank_ == 0; }
  bool distributed() const { return ranks_ > 1; }
  // This rank among the ranks of its host, and how many those are.
  int local_rank() const { return local_rank_; }
  int local_ranks() const { return local_ranks_; }
  const std::string& host() const { return host_; }
  // "rank 2 of 3": how messages name a rank (with its host, where they know it).
  std::string name(int rank) const;

  // Rank 0 gets every rank's text in rank order; the others get nothing.
  std::vector<std::string> gather(const std::string& mine) const;
  // Every rank gets rank 0's text.
  std::string broadcast(const std::string& from_root) const;
  // Rank 0 adds every other rank's values (as many as its own) to its own, in rank
  // order, so that the sum is the same whatever the timing; the others' are sent.
  void sum_to_root(std::vector<float>& values) const;
  // Point to point (not collective): a text to one rank, a text from one rank with
  // this tag, a text from any rank with any tag.
  void send(int to, int tag, const std::string& text) const;
  std::string receive(int from, int tag) const;
  ClusterMessage receive_any() const;

 private:
  int rank_ = 0, ranks_ = 1, local_rank_ = 0, local_ranks_ = 1;
  std::string host_;
  std::shared_ptr<Transport> transport_;
};

// Whether this build can run as MPI ranks.
bool built_with_mpi();
// Starts MPI where an MPI launcher started this process (and the build has MPI; unless
// kSingleProcessVariable is set); otherwise a cluster of one. Throws std::runtime_error
// for a process launched as one of several ranks by a build without MPI, and where MPI
// cannot give the threading the batch needs.
Cluster start_cluster(int* argc, char*** argv);
// Ends MPI where start_cluster started it (every rank, once, at the end).
void end_cluster();
// Ends every rank of the run at once with `code`: for a rank that fails where the
// others cannot learn of it (its command line), which would leave them waiting.
[[noreturn]] void abort_cluster(int code);

}  // namespace wt::app
