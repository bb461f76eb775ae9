// The jobs-file reader over arbitrary file contents: batch_input and read_jobs_file
// each either answer or throw InputError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "app/jobs_file.hpp"
#include "errors/errors.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = wt::fuzz::write_input("jobs.json", data, size);
  try {
    wt::app::batch_input(path);
  } catch (const wt::InputError&) {
  }
  try {
    wt::app::read_jobs_file(path, wt::app::Job{});
  } catch (const wt::InputError&) {
  }
  return 0;
}
