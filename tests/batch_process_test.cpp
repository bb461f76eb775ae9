// `wavetrace batch` runs its jobs in processes of its own (run_batch_in_processes): a
// worker per lane that renders job after job, or `wavetrace render` for each job.
// Here: a job becomes a command line that parses back into the same job, and the
// batch's handling of its children, with small shell scripts standing in for the
// program (tests/command/ runs the real binary).
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include "app/batch.hpp"
#include "app/cli.hpp"
#include "app/process.hpp"
#include "errors/errors.hpp"
#include "test_support.hpp"

namespace wt::app {
namespace {

namespace fs = std::filesystem;

// Every field of a Job.
auto fields(const Job& j) {
  return std::tie(j.scene, j.output, j.stats, j.width, j.height, j.spp, j.depth, j.roulette_depth, j.seed, j.backend,
                  j.kernel, j.warmup, j.wave_size, j.threads, j.devices, j.checkpoint, j.resume, j.checkpoint_every,
                  j.encoding, j.exr_float, j.progress, j.profile, j.denoise, j.denoise_quality, j.keep_noisy,
                  j.aov, j.megakernel_batch, j.noise_threshold, j.min_spp);
}


TEST(BatchProcess, AJobBecomesRenderArgumentsThatParseBackIntoTheSameJob) {
  Job every;
  every.scene = "-scene with spaces.json";  // a leading '-' must not read as an option
  every.output = "-out.pfm";
  every.stats = "s.json";
  every.width = 33;
  every.height = 17;
  every.spp = 5;
  every.depth = 7;
  every.roulette_depth = 0;
  every.seed = 4294967295;
  every.backend = "cuda";
  every.kernel = "wavefront-unsorted";
  every.warmup = 3;
  every.wave_size = 4096;
  every.threads = 2;
  every.devices = "1,0";
  every.checkpoint = "c.ckpt";
  every.resume = "r.ckpt";
  every.checkpoint_every = 9;
  every.encoding = Encoding::Gamma2;
  every.exr_float = true;
  every.progress = false;
  every.profile = true;
  every.denoise = true;
  every.denoise_quality = "balanced";
  every.keep_noisy = true;
  every.aov = "position,albedo";
  every.megakernel_batch = 7;
  every.noise_threshold = 0.0123456789012345;
  every.min_spp = 12;
  Job defaults;
  defaults.scene = "s.json";
  defaults.output = "o.png";
  for (const Job& job : {every, defaults}) {
    const std::vector<std::string> args = render_arguments(job);
    EXPECT_EQ(args.front(), "render");
    const Job back = parse_render_arguments(args);
    EXPECT_TRUE(fields(back) == fields(job)) << job.scene;
  }
  // A default job's settings stay unset, so that the scene's own apply.
  EXPECT_FALSE(parse_render_arguments({"render", "-o", "o.png", "s.json"}).width.has_value());
}

TEST(RenderCommand, ExrFloatIsAFlagThatIsOffByDefault) {
  EXPECT_TRUE(parse_render_arguments({"render", "-o", "o.exr", "--exr-float", "s.json"}).exr_float);
  EXPECT_FALSE(parse_render_arguments({"render", "-o", "o.exr", "s.json"}).exr_float);
  EXPECT_THROW(parse_render_arguments({"render", "-o", "o.exr", "--exr-float=maybe", "s.json"}), CLI::ParseError);
}

class BatchProcessTest : public testing::Test {
 protected:

  // A shell script standing in for the program: `body` runs with the job's arguments.
  std::string script(const std::string& body) const {
    const std::string p = (dir_ / "fake-wavetrace").string();
    std::ofstream(p) << "#!/bin/sh\n" << body << "\n";
    ::chmod(p.c_str(), 0755);
    return p;
  }

  std::vector<PlannedJob> jobs(int n) const {
    std::vector<PlannedJob> list;
    for (int i = 0; i < n; ++i) {
      Job j;
      j.scene = "s.json";
      j.output = (dir_ / ("out" + std::to_string(i) + ".png")).string();
      list.push_back({j, ""});
    }
    return list;
  }

  // Runs the batch with the script; its exit code, and what it wrote to stdout and stderr.
  std::tuple<int, std::string, std::string> batch(const std::string& exe, const std::vector<PlannedJob>& list,
                                                  bool skip_done = false,
                                                  const std::vector<std::string>& lanes = {""},
                                                  JobProcesses processes = JobProcesses::PerJob) const {
    testing::internal::CaptureStdout();
    testing::internal::CaptureStderr();
    const int code = run_batch_in_processes(list, skip_done, exe, lanes, Cluster(), processes);
    std::string out = testing::internal::GetCapturedStdout();
    return {code, out, testing::internal::GetCapturedStderr()};
  }

  test::TestFolder folder_;
  const fs::path dir_ = folder_.root();
};

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST_F(BatchProcessTest, AChildsLastLineIsItsMessageAndItsOtherOutputIsForwarded) {
  const std::string exe = script(R"(echo "progress" >&2
echo "wavetrace: a notice" >&2
echo "wavetrace: the job failed because of X" >&2
exit 2)");
  const auto [code, out, err] = batch(exe, jobs(2));
  EXPECT_EQ(code, kExitFailure);
  EXPECT_EQ(count(out, "FAILED: the job failed because of X"), 2u) << out;
  EXPECT_NE(out.find("2 jobs: 0 ok, 2 failed"), std::string::npos) << out;
  // Each line once: the last one from the batch, the others forwarded as they came.
  EXPECT_EQ(count(err, "wavetrace: the job failed because of X\n"), 2u) << err;
  EXPECT_EQ(count(err, "wavetrace: a notice\n"), 2u) << err;
  EXPECT_EQ(count(err, "progress\n"), 2u) << err;
}

TEST_F(BatchProcessTest, AChildKilledByASignalFailsItsJobAloneAndSaysSo) {
  const auto [code, out, err] = batch(script("kill -SEGV $$"), jobs(2));
  EXPECT_EQ(code, kExitFailure);
  const std::string line = "the job's process was killed by signal " + std::to_string(SIGSEGV) + " (" +
                           strsignal(SIGSEGV) + ")";
  EXPECT_EQ(count(out, "FAILED: " + line), 2u) << out;
  EXPECT_EQ(count(err, "wavetrace: " + line), 2u) << err;
}

TEST_F(BatchProcessTest, ExitWithoutALineIsReportedWithItsCode) {
  const auto [code, out, err] = batch(script("exit 3"), jobs(1));
  EXPECT_EQ(code, kExitFailure);
  EXPECT_NE(out.find("FAILED: the job's process exited with 3 without saying why"), std::string::npos) << out;
}

TEST_F(BatchProcessTest, TheJobGetsItsArgumentsAndAStatsFileThatIsRemovedAfterwards) {
  // The child records its arguments, and writes the stats file it was given.
  const std::string exe = script(R"(printf '%s\n' "$@" > ")" + (dir_ / "args").string() + R"("
for a in "$@"; do case "$a" in --stats=*) printf '%s' '{"settings": {"width": 7, "height": 5, "spp": 3, "depth": 2},
 "backend": "cpu", "kernel": "wavefront", "seconds": 2.0, "rays": 8000000}' > "${a#--stats=}"; echo "${a#--stats=}" > ")" + (dir_ / "stats-path").string() + R"(";; esac; done)");
  std::vector<PlannedJob> list = jobs(1);
  list[0].job.seed = 9;
  const auto [code, out, err] = batch(exe, list);
  EXPECT_EQ(code, 0) << err;
  std::vector<std::string> args;
  std::ifstream in(dir_ / "args");
  for (std::string a; std::getline(in, a);) args.push_back(a);
  EXPECT_EQ(args, render_arguments([&] {
              Job j = list[0].job;
              j.stats = args.size() > 2 ? args[2].substr(std::string("--stats=").size()) : "";
              return j;
            }()));
  std::string stats;
  std::getline(std::ifstream(dir_ / "stats-path"), stats);
  EXPECT_EQ(fs::path(stats).extension(), ".json");
  EXPECT_FALSE(fs::exists(stats));  // the temporary stats file is gone
  EXPECT_NE(out.find("7x5 3spp d2"), std::string::npos) << out;
  EXPECT_NE(out.find("cpu/wavefront"), std::string::npos) << out;
  EXPECT_NE(out.find("    2.000       4.00  ok -> "), std::string::npos) << out;
}

// Lanes run at once: each job marks that it started and waits (up to 20 s, then
// fails) until two jobs have, which only jobs running at the same time can do. Each
// lane's jobs get its devices; the summary lists the jobs in the batch's order.
TEST_F(BatchProcessTest, LanesRunJobsAtOnceEachOnItsDevices) {
  const std::string started = (dir_ / "started").string();
  const std::string exe = script(R"sh(for a in "$@"; do case "$a" in --devices=*) d="${a#--devices=}";; esac; done
echo "$d" >> ")sh" + (dir_ / "devices").string() + R"sh("
mkdir -p ")sh" + started + R"sh(" && touch ")sh" + started + R"sh(/$$"
n=0
while [ "$(ls ")sh" + started + R"sh(" | wc -l)" -lt 2 ]; do
  n=$((n + 1)); [ $n -gt 200 ] && { echo "wavetrace: alone" >&2; exit 3; }
  sleep 0.1
done
exit 0)sh");
  const auto [code, out, err] = batch(exe, jobs(4), false, {"0", "1"});
  EXPECT_EQ(code, 0) << out << err;
  EXPECT_NE(out.find("4 jobs: 4 ok, 0 failed"), std::string::npos) << out;
  for (int i = 1; i <= 4; ++i) {
    EXPECT_NE(out.find(std::to_string(i) + "    s.json"), std::string::npos) << out;
  }
  EXPECT_LT(out.find("1    s.json"), out.find("4    s.json")) << out;
  std::vector<std::string> devices;
  std::ifstream in(dir_ / "devices");
  for (std::string d; std::getline(in, d);) devices.push_back(d);
  ASSERT_EQ(devices.size(), 4u);
  EXPECT_EQ(std::count(devices.begin(), devices.end(), "0") + std::count(devices.begin(), devices.end(), "1"), 4);
  EXPECT_GE(std::count(devices.begin(), devices.end(), "0"), 1);
  EXPECT_GE(std::count(devices.begin(), devices.end(), "1"), 1);
}

TEST(BatchLanes, ADeviceEachOrAShareOfThemEach) {
  EXPECT_EQ(batch_lanes("all", "auto", 16, 2), (std::vector<std::string>{"0", "1"}));
  EXPECT_EQ(batch_lanes("all", "cuda", 1, 2), (std::vector<std::string>{"0,1"}));
  EXPECT_EQ(batch_lanes("0,1,2,3", "cuda", 2, 4), (std::vector<std::string>{"0,2", "1,3"}));
  EXPECT_EQ(batch_lanes("1", "cuda", 5, 2), (std::vector<std::string>{"1"}));
  EXPECT_EQ(batch_lanes("all", "cuda", 5, 1), (std::vector<std::string>{""}));
  EXPECT_EQ(batch_lanes("all", "cpu", 5, 2), (std::vector<std::string>{""}));
  EXPECT_EQ(batch_lanes("all", "auto", 5, 0), (std::vector<std::string>{""}));
  EXPECT_THROW(batch_lanes("0,7", "cuda", 5, 2), InputError);
}

TEST_F(BatchProcessTest, ResumeSkipsJobsWhoseImageExists) {
  std::vector<PlannedJob> list = jobs(2);
  std::ofstream(list[0].job.output) << "done";
  const auto [code, out, err] = batch(script("exit 0"), list, true);
  EXPECT_EQ(code, 0);
  EXPECT_NE(out.find("skipped: " + list[0].job.output + " exists"), std::string::npos) << out;
  EXPECT_EQ(count(err, "[2/2]"), 1u) << err;
}

// SIGTERM sent to the batch reaches the running job (the script sends it to its
// parent, the batch, and waits for it to come back); the batch stops after that job
// with 128 + the signal, whether the job writes a checkpoint and exits or dies of it.
TEST_F(BatchProcessTest, SigtermToTheBatchIsPassedOnToTheJobAndStopsTheBatch) {
  const std::string checkpointed = script(R"(trap 'echo "wavetrace: interrupted by SIGTERM; checkpoint written" >&2; exit 143' TERM
kill -TERM $PPID
while :; do sleep 1; done)");
  auto [code, out, err] = batch(checkpointed, jobs(3));
  EXPECT_EQ(code, 128 + SIGTERM);
  EXPECT_NE(out.find("FAILED: interrupted by SIGTERM; checkpoint written"), std::string::npos) << out;
  EXPECT_NE(out.find("1 jobs: 0 ok, 1 failed; interrupted, 2 not run"), std::string::npos) << out;

  std::tie(code, out, err) = batch(script("kill -TERM $PPID\nwhile :; do sleep 1; done"), jobs(3));
  EXPECT_EQ(code, 128 + SIGTERM);
  EXPECT_NE(out.find("FAILED: the job's process was killed by SIGTERM"), std::string::npos) << out;
  EXPECT_NE(out.find("interrupted, 2 not run"), std::string::npos) << out;
}

// Shell scripts standing in for `wavetrace worker`: each reads its questions, a line
// each, logs "PID ..." for each, and answers on descriptor 3.
TEST_F(BatchProcessTest, AWorkerPerLaneRendersItsJobsOneAfterAnother) {
  const std::string log = (dir_ / "log").string();
  const std::string exe = script(R"sh([ "$1" = worker ] || exit 9
while read -r line; do
  i=$(printf '%s' "$line" | sed 's/.*"index":\([0-9]*\).*/\1/')
  d=$(printf '%s' "$line" | sed -n 's/.*"--devices=\([0-9,]*\)".*/\1/p')
  echo "$$ $d" >> ")sh" + log + R"sh("
  echo "{\"index\":$i,\"exit_code\":0,\"backend\":\"cpu\",\"kernel\":\"wavefront\",\"width\":7,\"height\":5,\"spp\":3,\"depth\":2,\"seconds\":2.0,\"rays\":8000000}" >&3
done)sh");
  auto [code, out, err] = batch(exe, jobs(3), false, {""}, JobProcesses::PerLane);
  EXPECT_EQ(code, 0) << out << err;
  EXPECT_NE(out.find("3 jobs: 3 ok, 0 failed"), std::string::npos) << out;
  EXPECT_EQ(count(out, "7x5 3spp d2"), 3u) << out;
  EXPECT_EQ(count(out, "cpu/wavefront"), 3u) << out;
  EXPECT_EQ(count(out, "    2.000       4.00  ok -> "), 3u) << out;
  std::ifstream in(log);
  std::vector<std::string> seen;
  for (std::string l; std::getline(in, l);) seen.push_back(l);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), seen[0]), 3) << "one worker for the three jobs";

  // Two lanes: a worker each, each with its lane's devices.
  fs::remove(log);
  std::tie(code, out, err) = batch(exe, jobs(6), false, {"0", "1"}, JobProcesses::PerLane);
  EXPECT_EQ(code, 0) << out << err;
  EXPECT_NE(out.find("6 jobs: 6 ok, 0 failed"), std::string::npos) << out;
  std::ifstream again(log);
  std::map<std::string, std::set<std::string>> devices_of;  // worker pid -> the devices its jobs named
  int jobs_seen = 0;
  for (std::string pid, devices; again >> pid >> devices; ++jobs_seen) devices_of[pid].insert(devices);
  EXPECT_EQ(jobs_seen, 6);
  EXPECT_LE(devices_of.size(), 2u);
  for (const auto& [pid, devices] : devices_of) EXPECT_EQ(devices.size(), 1u) << "worker " << pid;
}

// A job that lost the CUDA context, a worker killed mid-job and one that exits
// without answering: each fails its job alone, and the lane's next job starts a new
// worker, which renders it.
TEST_F(BatchProcessTest, AJobThatEndsItsWorkerFailsAloneAndTheNextStartsANewOne) {
  const std::string log = (dir_ / "log").string();
  const std::string exe = script(R"sh([ "$1" = worker ] || exit 9
while read -r line; do
  i=$(printf '%s' "$line" | sed 's/.*"index":\([0-9]*\).*/\1/')
  echo "$$ $i" >> ")sh" + log + R"sh("
  case $i in
    0) echo "{\"index\":0,\"exit_code\":1,\"message\":\"cuda: illegal address\",\"device_lost\":true}" >&3; exit 1;;
    2) kill -SEGV $$;;
    4) exit 3;;
    *) echo "{\"index\":$i,\"exit_code\":0,\"backend\":\"cpu\",\"kernel\":\"megakernel\"}" >&3;;
  esac
done)sh");
  const auto [code, out, err] = batch(exe, jobs(6), false, {""}, JobProcesses::PerLane);
  EXPECT_EQ(code, kExitFailure) << out << err;
  EXPECT_NE(out.find("6 jobs: 3 ok, 3 failed"), std::string::npos) << out;
  EXPECT_EQ(count(out, "FAILED: cuda: illegal address"), 1u) << out;
  EXPECT_EQ(count(out, "FAILED: the job's process was killed by signal " + std::to_string(SIGSEGV) + " (" +
                           strsignal(SIGSEGV) + ")"),
            1u)
      << out;
  EXPECT_EQ(count(out, "FAILED: the job's process exited with 3 without saying why"), 1u) << out;
  EXPECT_EQ(count(err, "wavetrace: cuda: illegal address\n"), 1u) << err;
  // Workers: {0}, {1, 2}, {3, 4}, {5}.
  std::ifstream in(log);
  std::vector<std::pair<std::string, int>> seen;
  std::string pid;
  for (int i = 0; in >> pid >> i;) seen.emplace_back(pid, i);
  ASSERT_EQ(seen.size(), 6u);
  std::set<std::string> pids;
  for (const auto& p : seen) pids.insert(p.first);
  EXPECT_EQ(pids.size(), 4u);
  EXPECT_NE(seen[0].first, seen[1].first);
  EXPECT_EQ(seen[1].first, seen[2].first);
  EXPECT_NE(seen[2].first, seen[3].first);
  EXPECT_EQ(seen[3].first, seen[4].first);
  EXPECT_NE(seen[4].first, seen[5].first);
}

// A lane with no job left ends its worker at once (freeing its GPU, or letting its
// teardown overlap the other lanes' work), not at the end of the batch: the second
// lane's job here waits for the first lane's worker to have ended.
TEST_F(BatchProcessTest, ALaneOutOfJobsEndsItsWorkerWhileTheOtherLanesWork) {
  const std::string started = (dir_ / "started1").string(), ended = (dir_ / "ended0").string();
  const std::string exe = script(R"sh([ "$1" = worker ] || exit 9
wait_for() { n=0; while [ ! -e "$1" ] && [ $n -lt 100 ]; do sleep 0.05; n=$((n+1)); done; [ -e "$1" ]; }
lane=none
while read -r line; do
  i=$(printf '%s' "$line" | sed 's/.*"index":\([0-9]*\).*/\1/')
  lane=$(printf '%s' "$line" | sed -n 's/.*"--devices=\([0-9,]*\)".*/\1/p')
  if [ "$lane" = 0 ]; then
    wait_for ")sh" + started + R"sh("
  else
    touch ")sh" + started + R"sh("
    if ! wait_for ")sh" + ended + R"sh("; then
      echo "{\"index\":$i,\"exit_code\":1,\"message\":\"the other lane's worker still runs\"}" >&3
      continue
    fi
  fi
  echo "{\"index\":$i,\"exit_code\":0,\"backend\":\"cuda\",\"kernel\":\"wavefront\"}" >&3
done
[ "$lane" = 0 ] && touch ")sh" + ended + R"sh("
exit 0)sh");
  const auto [code, out, err] = batch(exe, jobs(2), false, {"0", "1"}, JobProcesses::PerLane);
  EXPECT_EQ(code, 0) << out << err;
  EXPECT_NE(out.find("2 jobs: 2 ok, 0 failed"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(started)) << "the second lane ran no job";
}

// A worker killed while it waits for its next question (from outside: the kernel's
// out-of-memory killer, a user) is replaced before the question is sent, so the job
// is asked of a live worker rather than failed.
TEST_F(BatchProcessTest, AWorkerKilledWhileItWaitsIsReplacedBeforeTheNextQuestion) {
  const std::string exe = script(R"sh([ "$1" = worker ] || exit 9
while read -r line; do echo "$$ $line" >&3; done)sh");
  WorkerProcess worker(exe);
  ChildEnd end;
  const std::optional<std::string> first = worker.ask("a", end);
  ASSERT_TRUE(first.has_value());
  const pid_t pid = worker.pid();
  EXPECT_EQ(*first, std::to_string(pid) + " a");
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  siginfo_t info{};
  ASSERT_EQ(::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT), 0);  // dead, not yet reaped
  const std::optional<std::string> second = worker.ask("b", end);
  ASSERT_TRUE(second.has_value()) << "the question went to the dead worker";
  EXPECT_NE(worker.pid(), pid);
  EXPECT_EQ(*second, std::to_string(worker.pid()) + " b");
  const ChildEnd stopped = worker.stop();
  EXPECT_TRUE(stopped.exited);
  EXPECT_EQ(stopped.exit_code, 0);
  EXPECT_EQ(worker.pid(), 0);
}

// SIGTERM sent to the batch reaches the worker rendering a job; the batch stops.
TEST_F(BatchProcessTest, SigtermToTheBatchReachesTheWorkerAndStopsTheBatch) {
  const std::string exe = script(R"sh([ "$1" = worker ] || exit 9
read -r line
kill -TERM $PPID
while :; do sleep 1; done)sh");
  const auto [code, out, err] = batch(exe, jobs(3), false, {""}, JobProcesses::PerLane);
  EXPECT_EQ(code, 128 + SIGTERM);
  EXPECT_NE(out.find("FAILED: the job's process was killed by SIGTERM"), std::string::npos) << out;
  EXPECT_NE(out.find("interrupted, 2 not run"), std::string::npos) << out;
}

}  // namespace
}  // namespace wt::app
