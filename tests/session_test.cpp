// A render session (app/session.hpp), the Python module's renderer: how often it
// asks its watchers. A render tells its progress often (each bounce of a wavefront,
// each chunk of rows of the CPU megakernel); the session passes that on to the
// caller's progress and stop at most every 10 ms, and tells 1 once at the end, so
// that a caller that must take a lock to look (the module takes the GIL) does not
// slow the render.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "app/session.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using Clock = std::chrono::steady_clock;

app::Session cornell_session() {
  const std::string path = test::repo_path("scenes/cornell-box.json");
  return app::Session(std::make_shared<const Scene>(load_scene(path)), path);
}

app::Job cpu_job(const std::string& kernel) {
  app::Job job;
  job.backend = "cpu";
  job.kernel = kernel;
  job.width = 96;
  job.height = 72;
  job.spp = 32;
  job.threads = 1;         // one thread: many short chunks of rows, each told
  job.wave_size = 4096;    // small waves: many short bounces, each told
  job.progress = false;
  return job;
}

// Asks come at least 10 ms apart; progress rises to 1, told once, last. The render
// itself tells its progress far more often (hundreds of bounces or chunks a second,
// and a wavefront tells 1 twice), which neither would hold for.
TEST(Session, AsksItsWatchersAtMostEveryTenMillisecondsAndTellsTheEndOnce) {
  const app::Session session = cornell_session();
  for (const std::string kernel : {"megakernel", "wavefront"}) {
    std::vector<double> done;
    std::vector<Clock::time_point> asked;
    const Clock::time_point start = Clock::now();
    const app::SessionRender r = session.render(
        cpu_job(kernel), [&](double d) { done.push_back(d); },
        [&] {
          asked.push_back(Clock::now());
          return false;
        });
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    ASSERT_FALSE(r.outcome.result.interrupted) << kernel;
    ASSERT_FALSE(done.empty()) << kernel;
    EXPECT_EQ(done.back(), 1.0) << kernel;
    EXPECT_EQ(std::count(done.begin(), done.end(), 1.0), 1) << kernel;
    EXPECT_TRUE(std::is_sorted(done.begin(), done.end())) << kernel;
    for (size_t i = 1; i < asked.size(); ++i) {
      EXPECT_GE(asked[i] - asked[i - 1], std::chrono::milliseconds(10)) << kernel << " ask " << i;
    }
    EXPECT_LE(asked.size(), static_cast<size_t>(seconds / 0.010) + 1) << kernel << ": " << seconds << " s";
    // The render ran long enough to be asked more than once on its way.
    EXPECT_GE(asked.size(), 3u) << kernel << ": " << seconds << " s";
  }
}

// A stop that says yes at its first ask ends the render there: interrupted, with no
// image.
TEST(Session, AStopEndsTheRenderAtItsFirstAsk) {
  const app::Session session = cornell_session();
  int asks = 0;
  const app::SessionRender r = session.render(cpu_job("wavefront"), {}, [&] {
    ++asks;
    return true;
  });
  EXPECT_EQ(asks, 1);
  EXPECT_TRUE(r.outcome.result.interrupted);
  EXPECT_TRUE(r.outcome.result.rgb.empty());
}

}  // namespace
}  // namespace wt
