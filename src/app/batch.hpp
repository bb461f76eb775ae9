#pragma once

#include <string>
#include <vector>

#include "app/job.hpp"
#include "app/jobs_file.hpp"

namespace wt::app {

// Runs every job in this process, prints a summary table, returns the exit code
// (non-zero if any failed). `skip_done`: jobs whose image exists are skipped (a batch
// resumed). A job stopped by a signal stops the batch, whose exit code is then the
// job's. A job that meets a sticky CUDA error loses this process's CUDA context: the
// CUDA jobs after it (backend cuda or auto) fail at once with one line saying so, and
// the CPU jobs still run.
int run_batch(const std::vector<PlannedJob>& jobs, bool skip_done = false);

// `wavetrace batch`: the same, with the jobs run in processes of their own, so that a
// job that loses its CUDA context (a sticky error) or crashes fails alone. By default
// a lane keeps one worker process (`executable worker`, run_batch_worker) that renders
// its jobs one after another, set up once; a job that loses the worker's CUDA context,
// is interrupted by a signal or kills the worker ends it, and the lane's next job
// starts a new one. JobProcesses::PerJob runs each job as `executable render ...` in a
// process of its own (render_arguments) instead: a clean CUDA context for every job,
// at the price of the process's and the context's set-up every job. SIGINT and
// SIGTERM sent to this process are passed on to the running jobs, and the batch stops
// after them with 128 + the signal; a job killed by another signal fails alone. This
// process renders nothing itself.
// The lanes a batch runs its jobs in at once (run_batch_in_processes): one per CUDA
// device of `devices` ("all" or a list; `present` devices), or with fewer jobs than
// devices one per job, each over its share of them; a single lane ("": the jobs'
// own devices) on the CPU backend or with one device. Throws InputError for a bad list.
// Of an MPI run, the ranks on one host share its devices out (distributed.hpp's local_share).
std::vector<std::string> batch_lanes(const std::string& devices, const std::string& backend, size_t jobs,
                                     int present, const Cluster& cluster = Cluster());

// Runs each job as `wavetrace render` in a process of its own, the lanes' jobs at once.
// As a rank of an MPI run (every rank calls it), rank 0 hands the jobs of `jobs` out
// to every rank's lanes as they free up and alone prints the summary; the other
// ranks' `jobs` are not read.
// A lane with no job left ends its worker at once.
enum class JobProcesses { PerLane, PerJob };
int run_batch_in_processes(const std::vector<PlannedJob>& jobs, bool skip_done, const std::string& executable,
                           const std::vector<std::string>& lanes = {""}, const Cluster& cluster = Cluster(),
                           JobProcesses processes = JobProcesses::PerLane);

// `wavetrace worker`, the process a batch lane keeps: reads questions from stdin, a
// line each ({"index": N, "args": the job's render_arguments}), renders each job as
// `render` would (printing its result line to stderr), and answers on descriptor
// `answers` with a line of the job's outcome. Ends at the end of its input, after a
// job that lost the CUDA context (kExitFailure) or that a signal interrupted (its code).
int run_batch_worker(int answers = 3);

// Rank 0 of an MPI batch that has no jobs to give (its jobs file was refused): tells
// the other ranks' lanes so, which then end (the others call run_batch_in_processes).
void release_ranks(const Cluster& cluster);

}  // namespace wt::app
