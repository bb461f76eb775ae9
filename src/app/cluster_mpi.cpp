// The cluster over MPI (built where CMake finds MPI: Debian's libopenmpi-dev).
#include <mpi.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "app/cluster.hpp"
#include "app/cluster_launch.hpp"

namespace wt::app {

namespace {

bool g_started = false;

// An MPI call that failed: what it was, and what MPI says of it.
void check(int code, const char* call) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(std::string("MPI: ") + call + " failed: " + std::string(text, length));
}

int count_of(size_t n, const char* what) {
  if (n > static_cast<size_t>(INT_MAX)) {
    throw std::runtime_error(std::string("MPI: ") + what + " of " + std::to_string(n) +
                             " values is more than one message holds");
  }
  return static_cast<int>(n);
}

class MpiTransport final : public Cluster::Transport {
 public:
  explicit MpiTransport(int rank) : rank_(rank) {}

  std::vector<std::string> gather(const std::string& mine) override {
    int ranks = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    const int length = count_of(mine.size(), "a text");
    std::vector<int> lengths(rank_ == 0 ? ranks : 0);
    check(MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Gather");
    std::vector<int> offsets(lengths.size());
    size_t total = 0;
    for (size_t r = 0; r < lengths.size(); ++r) {
      offsets[r] = count_of(total, "the gathered texts");
      total += lengths[r];
    }
    std::string all(total, '\0');
    check(MPI_Gatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR, 0,
                      MPI_COMM_WORLD),
          "MPI_Gatherv");
    std::vector<std::string> out;
    for (size_t r = 0; r < lengths.size(); ++r) out.push_back(all.substr(offsets[r], lengths[r]));
    return out;
  }

  std::string broadcast(const std::string& from_root) override {
    int length = rank_ == 0 ? count_of(from_root.size(), "a text") : 0;
    check(MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Bcast");
    std::string text = rank_ == 0 ? from_root : std::string(length, '\0');
    check(MPI_Bcast(text.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
    return text;
  }

  void sum_to_root(std::vector<float>& values) override {
    const int n = count_of(values.size(), "a film");
    if (rank_ != 0) {
      check(MPI_Send(values.data(), n, MPI_FLOAT, 0, kFilmTag, MPI_COMM_WORLD), "MPI_Send");
      return;
    }
    int ranks = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    std::vector<float> theirs(values.size());
    for (int r = 1; r < ranks; ++r) {
      check(MPI_Recv(theirs.data(), n, MPI_FLOAT, r, kFilmTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Recv");
      for (size_t i = 0; i < values.size(); ++i) values[i] += theirs[i];
    }
  }

  void send(int to, int tag, const std::string& text) override {
    check(MPI_Send(text.data(), count_of(text.size(), "a text"), MPI_CHAR, to, tag, MPI_COMM_WORLD), "MPI_Send");
  }

  std::string receive(int from, int tag) override { return take(from, tag).text; }

  ClusterMessage receive_any() override { return take(MPI_ANY_SOURCE, MPI_ANY_TAG); }

 private:
  static constexpr int kFilmTag = 32767;  // the upper bound MPI guarantees for tags

  ClusterMessage take(int from, int tag) {
    // A matched probe: the message probed is the one received, whatever other
    // threads of this rank receive meanwhile.
    MPI_Message message;
    MPI_Status status;
    check(MPI_Mprobe(from, tag, MPI_COMM_WORLD, &message, &status), "MPI_Mprobe");
    int length = 0;
    MPI_Get_count(&status, MPI_CHAR, &length);
    ClusterMessage m{status.MPI_SOURCE, status.MPI_TAG, std::string(length, '\0')};
    check(MPI_Mrecv(m.text.data(), length, MPI_CHAR, &message, MPI_STATUS_IGNORE), "MPI_Mrecv");
    return m;
  }

  int rank_;
};

}  // namespace

bool built_with_mpi() { return true; }

Cluster start_cluster(int* argc, char*** argv) {
  const int launched = launched_ranks();
  if (launched == 1) return Cluster();
  // The batch's lanes ask for jobs from threads of their own.
  int provided = 0;
  check(MPI_Init_thread(argc, argv, MPI_THREAD_MULTIPLE, &provided), "MPI_Init_thread");
  g_started = true;
  if (provided < MPI_THREAD_MULTIPLE) {
    throw std::runtime_error("MPI: this MPI library does not allow calls from several threads "
                             "(MPI_THREAD_MULTIPLE), which wavetrace's batch needs");
  }
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  int rank = 0, ranks = 1, local_rank = 0, local_ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (launched > 1 && ranks != launched) {
    // Tasks started without the launcher's MPI wiring (srun without --mpi) each see
    // themselves alone, and would each render and write the whole image.
    throw std::runtime_error("MPI: started as one of " + std::to_string(launched) + " tasks, but MPI sees " +
                             std::to_string(ranks) + " rank" + (ranks == 1 ? "" : "s") +
                             " (under Slurm, srun needs --mpi=pmix or the MPI plugin Slurm was built with)");
  }
  MPI_Comm host_comm;
  check(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &host_comm),
        "MPI_Comm_split_type");
  MPI_Comm_rank(host_comm, &local_rank);
  MPI_Comm_size(host_comm, &local_ranks);
  MPI_Comm_free(&host_comm);
  char host[MPI_MAX_PROCESSOR_NAME];
  int length = 0;
  MPI_Get_processor_name(host, &length);
  return Cluster(rank, ranks, local_rank, local_ranks, std::string(host, length),
                 std::make_shared<MpiTransport>(rank));
}

void end_cluster() {
  if (g_started) {
    g_started = false;
    MPI_Finalize();
  }
}

void abort_cluster(int code) {
  if (g_started) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

}  // namespace wt::app
