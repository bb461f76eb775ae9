// The wavetrace command: render one scene, or a batch of jobs.
#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <utility>

#include "app/batch.hpp"
#include "app/bench.hpp"
#include "app/cli.hpp"
#include "app/cluster.hpp"
#include "app/convert.hpp"
#include "app/job.hpp"
#include "app/job_files.hpp"
#include "device/device.hpp"
#include "errors/errors.hpp"
#include "render/settings.hpp"
#include "scene/json_reader.hpp"

using wt::app::Job;

namespace {

int run(int argc, char** argv, const wt::app::Cluster& cluster);

}  // namespace

int main(int argc, char** argv) {
  // A write past a file-size limit fails with EFBIG, which the writers report (their
  // temporary file removed), rather than killing the process.
  std::signal(SIGXFSZ, SIG_IGN);
  // Under an MPI launcher, this process is one rank of several (app/cluster.hpp).
  wt::app::Cluster cluster;
  try {
    cluster = wt::app::start_cluster(&argc, &argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wavetrace: %s\n", e.what());
    wt::app::end_cluster();
    return wt::app::kExitFailure;
  }
  const int code = run(argc, argv, cluster);
  wt::app::end_cluster();
  return code;
}

namespace {

using wt::app::Cluster;

// `wavetrace batch`'s command line.
struct BatchCommand {
  Job job;  // the render options every job starts from
  std::string encoding = "srgb";
  std::vector<std::string> inputs;
  std::string output_dir = ".";
  bool skip_done = false;
  bool process_per_job = false;
};

CLI::App* add_batch_command(CLI::App& app, BatchCommand& cmd) {
  CLI::App* batch = app.add_subcommand("batch", "render a jobs file, or several scene files");
  batch->add_option("inputs", cmd.inputs, "a jobs file ({\"jobs\": [...]}) or scene files")->required();
  batch->add_option("--output-dir", cmd.output_dir, "where scene files given directly are rendered to");
  batch->add_flag("--resume", cmd.skip_done, "skip the jobs whose image exists (a batch resumed)");
  batch->add_flag("--process-per-job", cmd.process_per_job,
                  "run each job in a process of its own (a clean CUDA context for every job) rather than in "
                  "a worker process per lane (set up once, replaced after a job that loses its context)");
  wt::app::add_render_options(*batch, cmd.job, cmd.encoding);
  return batch;
}

CLI::App* add_bench_command(CLI::App& app, wt::app::BenchOptions& options) {
  CLI::App* bench = app.add_subcommand("bench", "time a grid of scenes x configurations x kernels");
  bench->add_option("spec", options.spec, "bench spec (JSON), e.g. bench/study.json")->required();
  bench->add_option("-o,--output-dir", options.out_dir, "folder for results.json and results.csv")->required();
  bench->add_option("--backend", options.backend, "cuda, cpu or auto")->check(CLI::IsMember(wt::backend_choices()));
  bench->add_option("--only", options.only, "run one group of the spec");
  bench->add_option("--repeats", options.repeats, "timed runs per point (default: the spec's)")
      ->check(CLI::Range(1, wt::app::kMaxRepeats));
  bench->add_option("--commit", options.commit, "the commit being measured, recorded in the results");
  return bench;
}

// Bad input on the command line: one line and exit 2; of an MPI run, where the other
// ranks may have parsed theirs and wait for this one, the run ends here.
int refuse(const Cluster& cluster, const std::string& what) {
  if (cluster.distributed()) {
    std::fprintf(stderr, "wavetrace: %s: %s; the MPI run is stopped\n", cluster.name(cluster.rank()).c_str(),
                 what.c_str());
    std::fflush(stderr);
    wt::app::abort_cluster(wt::app::kExitBadInput);
  }
  std::fprintf(stderr, "wavetrace: %s\n", what.c_str());
  return wt::app::kExitBadInput;
}

// A first word that is no command, named as such (CLI11 would call it an argument)
// with the commands; empty where the first word is a command or an option.
std::string unknown_command(CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return "";
  try {
    app.get_subcommand(argv[1]);
    return "";
  } catch (const CLI::OptionNotFound&) {
  }
  const std::function<bool(const CLI::App*)> shown = [](const CLI::App* c) { return !c->get_group().empty(); };
  std::vector<std::string> commands;
  for (const CLI::App* c : std::as_const(app).get_subcommands(shown)) commands.push_back(c->get_name());
  return std::string("unknown command '") + argv[1] + "' (the commands: " + wt::listed(commands) + ")";
}

int run_render(Job job, const Cluster& cluster) {
  if (!cluster.root()) job.progress = false;
  const wt::app::JobOutcome o = wt::app::run_job(job, cluster);
  if (o.exit_code != 0) {
    // Of an MPI run, rank 0 says what failed where; every rank exits with its code.
    if (cluster.root()) std::fprintf(stderr, "wavetrace: %s\n", o.message.c_str());
    return o.exit_code;
  }
  if (cluster.root()) wt::app::print_outcome(job, o);
  return 0;
}

int run_kernels(const std::string& backend) {
  const std::vector<std::string> names =
      backend.empty() ? wt::kernel_names() : wt::kernel_names(backend == "cuda" ? wt::Backend::Cuda : wt::Backend::Cpu);
  for (const std::string& name : names) std::printf("%s\n", name.c_str());
  return 0;
}

int run_bench_command(const wt::app::BenchOptions& options, const Cluster& cluster) {
  if (cluster.distributed()) {
    if (cluster.root()) std::fprintf(stderr, "wavetrace: bench times one process; run it without mpirun\n");
    return wt::app::kExitBadInput;
  }
  try {
    return wt::app::run_bench(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wavetrace: %s\n", e.what());
    return wt::app::kExitBadInput;
  }
}

// The batch's jobs: one input that is a jobs file, or else a job for every scene
// file, rendered to DIR/<name>.png. Throws InputError.
std::vector<wt::app::PlannedJob> plan_batch(const BatchCommand& cmd, const Job& base) {
  const std::vector<std::string>& inputs = cmd.inputs;
  if (inputs.size() == 1 && wt::app::batch_input(inputs[0]) == wt::app::BatchInput::JobsFile) {
    return wt::app::read_jobs_file(inputs[0], base);
  }
  std::vector<wt::app::PlannedJob> jobs;
  for (const std::string& scene : inputs) {
    Job j = base;
    j.scene = scene;
    j.output = (std::filesystem::path(cmd.output_dir) / std::filesystem::path(scene).stem()).string() + ".png";
    jobs.push_back({j, ""});
  }
  return jobs;
}

// Throws InputError where jobs would write one file: refused together, before any runs.
void refuse_colliding(const std::vector<wt::app::PlannedJob>& jobs) {
  std::vector<Job> planned;
  std::vector<bool> refused;
  for (const wt::app::PlannedJob& pj : jobs) {
    planned.push_back(pj.job);
    refused.push_back(!pj.error.empty());
  }
  if (const std::string collision = wt::app::colliding_jobs(planned, refused); !collision.empty()) {
    throw wt::InputError(collision);
  }
}

int run_batch_command(const BatchCommand& cmd, const Cluster& cluster) {
  Job base = cmd.job;
  wt::app::set_encoding(base, cmd.encoding);
  const auto processes = cmd.process_per_job ? wt::app::JobProcesses::PerJob : wt::app::JobProcesses::PerLane;
  // Its jobs render alone, whatever MPI run the batch is a rank of.
  if (cluster.distributed()) setenv(wt::app::kSingleProcessVariable, "1", 1);
  if (!cluster.root()) {
    // Rank 0 reads the jobs and hands them out; this rank's lanes run what it gives.
    std::vector<std::string> lanes;
    try {
      lanes = wt::app::batch_lanes(base.devices, base.backend, SIZE_MAX, wt::cuda::device_count(), cluster);
    } catch (const wt::InputError&) {
      lanes = {""};  // rank 0 reads the same list, and says what is wrong with it
    }
    return wt::app::run_batch_in_processes({}, cmd.skip_done, "/proc/self/exe", lanes, cluster, processes);
  }
  // Each job runs in a process of its own (a worker per lane, or a `render` each): a
  // clean CUDA context, whatever the job before it did to its own. With several CUDA
  // devices the jobs run at once, a device (or a share of them) each.
  std::vector<wt::app::PlannedJob> jobs;
  std::vector<std::string> lanes;
  try {
    jobs = plan_batch(cmd, base);
    refuse_colliding(jobs);
    const int present = base.backend == "cpu" ? 0 : wt::cuda::device_count();
    lanes = wt::app::batch_lanes(base.devices, base.backend, jobs.size(), present, cluster);
  } catch (const wt::InputError& e) {
    std::fprintf(stderr, "wavetrace: %s\n", e.what());
    if (cluster.distributed()) wt::app::release_ranks(cluster);
    return wt::app::kExitBadInput;
  }
  return wt::app::run_batch_in_processes(jobs, cmd.skip_done, "/proc/self/exe", lanes, cluster, processes);
}

int run(int argc, char** argv, const Cluster& cluster) {
  CLI::App app{"wavetrace: a wavefront path tracer, with the megakernel kept for comparison"};
  app.require_subcommand(1);
  wt::app::RenderCommand render_command;
  CLI::App* render = wt::app::add_render_command(app, render_command);
  BatchCommand batch_command;
  add_batch_command(app, batch_command);
  // The process a batch lane keeps (app/batch.hpp); not for the command line.
  CLI::App* worker = app.add_subcommand("worker", "")->group("");
  wt::app::BenchOptions bench_options;
  CLI::App* bench = add_bench_command(app, bench_options);
  Job convert_job;  // its scene and parameters
  std::string convert_output;
  CLI::App* convert = app.add_subcommand("convert", "write a Mitsuba 3 scene (.xml) as the wavetrace scene (.json) it is read as");
  convert->add_option("scene", convert_job.scene, "the Mitsuba scene (.xml)")->required();
  convert->add_option("-o,--output", convert_output, "the wavetrace scene to write (.json)")->required();
  wt::app::add_define_option(*convert, convert_job);
  std::string kernels_backend;
  CLI::App* kernels = app.add_subcommand("kernels", "list the kernels, one a line, in the order the docs use");
  kernels->add_option("--backend", kernels_backend, "only those that run on this backend: cuda or cpu")
      ->check(CLI::IsMember({"cuda", "cpu"}));

  if (const std::string unknown = unknown_command(app, argc, argv); !unknown.empty()) return refuse(cluster, unknown);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    return refuse(cluster, e.what());
  } catch (const wt::InputError& e) {  // -D name=value
    return refuse(cluster, e.what());
  }
  if (*worker) return wt::app::run_batch_worker();
  if (*render) return run_render(render_command.parsed(), cluster);
  if (*kernels) return run_kernels(kernels_backend);
  if (*convert) return wt::app::run_convert(convert_job.scene, convert_output, convert_job.defines);
  if (*bench) return run_bench_command(bench_options, cluster);
  return run_batch_command(batch_command, cluster);  // the one command left (one is required)
}

}  // namespace
