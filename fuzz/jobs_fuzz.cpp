// The jobs-file reader over arbitrary file contents: is_jobs_file never throws,
// read_jobs_file either plans jobs or throws SceneError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "app/batch.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = wt::fuzz::write_input("jobs.json", data, size);
  wt::app::is_jobs_file(path);
  try {
    wt::app::read_jobs_file(path, wt::app::Job{});
  } catch (const wt::SceneError&) {
  }
  return 0;
}
