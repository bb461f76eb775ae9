// A batch's job in another process: as `wavetrace render` in a process of its own,
// or asked of the lane's worker (`wavetrace worker`), and the worker's side of that
// exchange: a line a question (the job's render arguments), a line an answer (its
// outcome, outcome_json). Internal to the batch.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "app/job.hpp"
#include "app/process.hpp"

namespace wt::app {

// A job's outcome as a line of JSON (what a worker answers, and a rank's lane says of
// the job it ran), and read back.
nlohmann::json outcome_json(size_t index, const JobOutcome& o);
JobOutcome outcome_of(const nlohmann::json& j);

// Runs one job as `executable render ...` in a process of its own.
JobOutcome run_job_in_process(const std::string& executable, size_t index, const Job& job,
                              const SignalForwarder& signals);

// Runs one job in the lane's worker (`wavetrace worker`, run_batch_worker). A job
// that lost the worker's CUDA context, or that a signal interrupted, ends the worker
// (the next job starts a new one); so does a worker that dies, failing its job alone.
JobOutcome run_job_in_worker(WorkerProcess& worker, size_t index, const Job& job, const SignalForwarder& signals);

}  // namespace wt::app
