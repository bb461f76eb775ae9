// Input files (src/scene/input_file.hpp): every file wavetrace reads is a regular
// file (or a link to one) within its kind's limit. What is not (missing, a directory,
// a FIFO, a device, a socket, a loop of links, too large) is refused at once with one
// line that names the path and says what it is, and never hangs: a FIFO without a
// writer would block an ordinary open or read forever, so every test that makes one
// runs under a test::Watchdog. The second half gives a FIFO and a directory to each
// real reader in turn (scene, jobs file, bench spec, meshes, material library, glTF
// buffer, texture and environment images, checkpoints): each must go through the
// same checks, and say the same.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "app/batch.hpp"
#include "app/bench.hpp"
#include "app/checkpoint.hpp"
#include "app/job.hpp"
#include "errors/errors.hpp"
#include "scene/input_file.hpp"
#include "scene/mesh_load.hpp"
#include "scene/scene.hpp"
#include "job_support.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// Long enough for a loaded machine, far shorter than a CI job's limit.
constexpr std::chrono::seconds kHangLimit = 30s;

constexpr InputKind kTestFile{"test file", 10};

void write_file(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

bool make_fifo(const fs::path& p) { return ::mkfifo(p.c_str(), 0600) == 0; }

// A UNIX socket bound to `p` (the file stays after the descriptor is closed).
bool make_socket(const fs::path& p) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  if (fd < 0) return false;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (p.string().size() >= sizeof addr.sun_path) {
    ::close(fd);
    return false;
  }
  std::strncpy(addr.sun_path, p.c_str(), sizeof addr.sun_path - 1);
  const bool bound = ::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  ::close(fd);
  return bound;
}

// What read_input_file threw (its line, and its reason), or "read N bytes".
struct Refusal {
  std::string line, reason;
};

Refusal refusal(const std::string& path, const InputKind& kind = kTestFile) {
  try {
    const std::string bytes = read_input_file(path, kind);
    return {"read " + std::to_string(bytes.size()) + " bytes", ""};
  } catch (const InputFileError& e) {
    return {e.what(), e.reason};
  }
}

class InputFile : public testing::Test {
 protected:
  std::string path(const std::string& name) const { return (folder_.root() / name).string(); }
  test::TestFolder folder_;
};

TEST_F(InputFile, ARegularFileIsReadWhole) {
  std::string bytes("a\0b\r\n\xff", 6);  // binary, with a NUL: read as it is
  write_file(path("f"), bytes);
  EXPECT_EQ(read_input_file(path("f"), kTestFile), bytes);
  write_file(path("empty"), "");
  EXPECT_EQ(read_input_file(path("empty"), kTestFile), "");
}

TEST_F(InputFile, ALinkToARegularFileIsReadThroughIt) {
  write_file(path("f"), "target");
  fs::create_symlink(path("f"), path("link"));
  fs::create_symlink("link", path("link-to-link"));  // relative, and a chain of two
  EXPECT_EQ(read_input_file(path("link"), kTestFile), "target");
  EXPECT_EQ(read_input_file(path("link-to-link"), kTestFile), "target");
}

TEST_F(InputFile, AMissingFileCannotBeOpened) {
  const Refusal r = refusal(path("missing"));
  EXPECT_EQ(r.line, path("missing") + ": cannot open test file (No such file or directory)");
  EXPECT_EQ(r.reason, "cannot open it (No such file or directory)");
  // An InputFileError is a InputError: every caller's bad-input handling takes it.
  EXPECT_THROW(read_input_file(path("missing"), kTestFile), InputError);
}

TEST_F(InputFile, ADirectoryIsRefused) {
  fs::create_directory(path("dir"));
  const Refusal r = refusal(path("dir"));
  EXPECT_EQ(r.line, path("dir") + ": cannot read test file: it is a directory, not a file");
  EXPECT_EQ(r.reason, "it is a directory, not a file");
}

// Without O_NONBLOCK the open alone would wait for a writer that never comes.
TEST_F(InputFile, AFifoIsRefusedWithoutWaitingForAWriter) {
  test::Watchdog watchdog(kHangLimit, "read_input_file on a FIFO");
  ASSERT_TRUE(make_fifo(path("fifo")));
  const Refusal r = refusal(path("fifo"));
  EXPECT_EQ(r.line, path("fifo") + ": cannot read test file: it is a FIFO (named pipe), not a regular file");
  EXPECT_EQ(r.reason, "it is a FIFO (named pipe), not a regular file");
}

// A FIFO whose writer is there and has written: still not a file (its "size" is
// whatever happens to be buffered, and a writer may never close it).
TEST_F(InputFile, AFifoWithAWriterIsRefusedToo) {
  test::Watchdog watchdog(kHangLimit, "read_input_file on a FIFO with a writer");
  ASSERT_TRUE(make_fifo(path("fifo")));
  const int reader = ::open(path("fifo").c_str(), O_RDONLY | O_NONBLOCK);  // so that the writer's open succeeds
  ASSERT_GE(reader, 0);
  const int writer = ::open(path("fifo").c_str(), O_WRONLY | O_NONBLOCK);
  ASSERT_GE(writer, 0);
  ASSERT_EQ(::write(writer, "{}", 2), 2);
  EXPECT_EQ(refusal(path("fifo")).reason, "it is a FIFO (named pipe), not a regular file");
  ::close(writer);
  ::close(reader);
}

// /dev/zero never ends: a reader that took it for a file would read without bound.
TEST_F(InputFile, CharacterDevicesAreRefused) {
  test::Watchdog watchdog(kHangLimit, "read_input_file on /dev/null and /dev/zero");
  for (const std::string device : {"/dev/null", "/dev/zero"}) {
    EXPECT_EQ(refusal(device).line, device + ": cannot read test file: it is a character device, not a regular file");
  }
}

// A socket cannot even be opened (ENXIO); the message says what it is rather than
// "No such device or address".
TEST_F(InputFile, ASocketIsRefused) {
  ASSERT_TRUE(make_socket(path("sock")));
  const Refusal r = refusal(path("sock"));
  EXPECT_EQ(r.line, path("sock") + ": cannot read test file: it is a socket, not a regular file");
  EXPECT_EQ(r.reason, "it is a socket, not a regular file");
}

TEST_F(InputFile, ALoopOfLinksSaysSo) {
  fs::create_symlink(path("b"), path("a"));
  fs::create_symlink(path("a"), path("b"));
  const Refusal r = refusal(path("a"));
  EXPECT_EQ(r.line, path("a") + ": cannot open test file (a loop of symbolic links)");
  EXPECT_EQ(r.reason, "cannot open it (a loop of symbolic links)");
}

TEST_F(InputFile, AFileOverItsKindsLimitIsRefused) {
  write_file(path("ten"), std::string(10, 'x'));
  EXPECT_EQ(read_input_file(path("ten"), kTestFile).size(), 10u);  // the limit itself is allowed
  write_file(path("eleven"), std::string(11, 'x'));
  const Refusal r = refusal(path("eleven"));
  EXPECT_EQ(r.line.rfind(path("eleven") + ": cannot read test file: it holds ", 0), 0u) << r.line;
  EXPECT_NE(r.line.find(", more than the "), std::string::npos) << r.line;
  EXPECT_NE(r.line.find(" a test file may hold"), std::string::npos) << r.line;
  EXPECT_EQ(r.line.find('\n'), std::string::npos) << r.line;
}

// A real kind's limit, on a sparse file (no disk used, and refused before a byte is read).
TEST_F(InputFile, ABenchSpecOverSixteenMibIsRefusedWithBothSizes) {
  {
    std::ofstream f(path("spec.json"));
  }
  fs::resize_file(path("spec.json"), 17 * input::kMiB);
  EXPECT_EQ(refusal(path("spec.json"), input::kBenchSpec).line,
            path("spec.json") + ": cannot read bench spec: it holds 17.0 MiB, more than the 16.0 MiB a bench spec "
                                "may hold");
}

// The watchdog itself: in a child process that hangs, it ends the child with 124.
TEST(Watchdog, EndsAProcessThatHangsWithExitCode124) {
  const std::string result = test::in_child_process([] {
    test::Watchdog watchdog(1s, "a test that sleeps");
    for (;;) ::pause();
    return std::string("woke");
  });
  EXPECT_EQ(result, "child process failed: status " + std::to_string(124 << 8) + " after \"\"");
}

TEST(Watchdog, OneDestroyedInTimeEndsNothing) {
  const auto start = std::chrono::steady_clock::now();
  { test::Watchdog watchdog(60s, "nothing"); }
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);  // its thread is woken, not waited out
}

// ---- A FIFO and a directory as each kind of input, through the real readers ----

enum class Bad { Fifo, Directory };

// A reader's refusal: exit code 2 with its line (a InputError, or a job's bad input),
// 0 where it did not refuse, or another code with what happened.
struct Outcome {
  int code = 0;
  std::string message;
};

template <class F>
Outcome outcome_of(F&& read) {
  try {
    read();
  } catch (const InputError& e) {
    return {app::kExitBadInput, e.what()};
  } catch (const std::exception& e) {
    return {99, std::string("not a InputError: ") + e.what()};
  }
  return {0, "no error"};
}

Outcome job_outcome(const app::Job& job) {
  const app::JobOutcome o = app::run_job(job);
  return {o.exit_code, o.message};
}

const char* kTinyScene = R"({
  "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
  "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
  "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]
})";

app::Job small_job(const fs::path& dir, const std::string& scene) {
  return test::small_job(scene, (dir / "out.pfm").string());
}

// A glTF of one triangle whose buffer is the file buffer.bin beside it.
const char* kGltfWithExternalBuffer = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"byteLength": 36, "uri": "buffer.bin"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}]})";

struct InputCase {
  const char* name;
  const char* bad_file;  // the input made a FIFO or a directory, in the test's folder
  // Writes what refers to the bad file (a scene, an OBJ...) and reads it.
  std::function<Outcome(const fs::path& dir, const std::string& bad)> read;
  bool job = false;  // run as a job: no image may be written
};

// For gtest's messages: the case by its name.
void PrintTo(const InputCase& c, std::ostream* os) { *os << c.name; }
void PrintTo(Bad b, std::ostream* os) { *os << (b == Bad::Fifo ? "a FIFO" : "a directory"); }

std::string write_in(const fs::path& dir, const std::string& name, const std::string& text) {
  write_file(dir / name, text);
  return (dir / name).string();
}

const InputCase kInputCases[] = {
    {"SceneFile", "scene.json", [](const fs::path&, const std::string& bad) {
       return outcome_of([&] { load_scene(bad); });
     }},
    {"SceneFileOfAJob", "scene.json",
     [](const fs::path& dir, const std::string& bad) { return job_outcome(small_job(dir, bad)); }, true},
    {"JobsFile", "jobs.json", [](const fs::path&, const std::string& bad) {
       return outcome_of([&] { app::read_jobs_file(bad, app::Job{}); });
     }},
    {"BatchInput", "jobs.json", [](const fs::path&, const std::string& bad) {
       return outcome_of([&] { app::batch_input(bad); });
     }},
    {"BenchSpec", "spec.json", [](const fs::path&, const std::string& bad) {
       return outcome_of([&] { app::read_bench_spec(bad, ""); });
     }},
    {"ObjMesh", "mesh.obj", [](const fs::path&, const std::string& bad) {
       return outcome_of([&] { load_mesh(bad); });
     }},
    {"GltfMesh", "mesh.gltf", [](const fs::path&, const std::string& bad) {
       return outcome_of([&] { load_mesh(bad); });
     }},
    {"GlbMesh", "mesh.glb", [](const fs::path&, const std::string& bad) {
       return outcome_of([&] { load_mesh(bad); });
     }},
    {"MeshOfAScene", "mesh.obj", [](const fs::path& dir, const std::string&) {
       const std::string scene = write_in(dir, "s.json", R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
         "materials": [{"name": "m", "type": "lambertian"}],
         "meshes": [{"name": "a", "file": "mesh.obj"}], "instances": [{"mesh": "a"}]})");
       return outcome_of([&] { load_scene(scene); });
     }},
    {"MaterialLibrary", "lib.mtl", [](const fs::path& dir, const std::string&) {
       const std::string obj = write_in(dir, "m.obj", "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
       return outcome_of([&] { load_mesh(obj); });
     }},
    {"GltfBuffer", "buffer.bin", [](const fs::path& dir, const std::string&) {
       const std::string gltf = write_in(dir, "m.gltf", kGltfWithExternalBuffer);
       return outcome_of([&] { load_mesh(gltf); });
     }},
    {"TextureImage", "picture.png", [](const fs::path& dir, const std::string&) {
       const std::string scene = write_in(dir, "s.json", R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
         "textures": [{"name": "t", "type": "image", "file": "picture.png"}],
         "materials": [{"name": "m", "type": "lambertian", "albedo": [1, 1, 1], "texture": "t"}],
         "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})");
       return outcome_of([&] { load_scene(scene); });
     }},
    {"EnvironmentImage", "sky.hdr", [](const fs::path& dir, const std::string&) {
       const std::string scene = write_in(dir, "s.json", R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
         "sky": {"type": "environment", "file": "sky.hdr"},
         "materials": [{"name": "m", "type": "lambertian"}],
         "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})");
       return outcome_of([&] { load_scene(scene); });
     }},
    // OpenEXR's reader, not stb's.
    {"EnvironmentExr", "sky.exr", [](const fs::path& dir, const std::string&) {
       const std::string scene = write_in(dir, "s.json", R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
         "sky": {"type": "environment", "file": "sky.exr"},
         "materials": [{"name": "m", "type": "lambertian"}],
         "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})");
       return outcome_of([&] { load_scene(scene); });
     }},
    // A mesh material's map_Kd, read when the scene takes the mesh's materials.
    {"TextureOfAMesh", "wood.png", [](const fs::path& dir, const std::string&) {
       write_in(dir, "lib.mtl", "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n");
       write_in(dir, "m.obj", "mtllib lib.mtl\nusemtl wood\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
       const std::string scene = write_in(dir, "s.json", R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
         "materials": [{"name": "m", "type": "lambertian"}],
         "meshes": [{"name": "a", "file": "m.obj"}], "instances": [{"mesh": "a"}]})");
       return outcome_of([&] { load_scene(scene); });
     }},
    {"Checkpoint", "c.ckpt", [](const fs::path&, const std::string& bad) {
       return outcome_of([&] { app::read_checkpoint(bad); });
     }},
    // --resume FILE --checkpoint OTHER: the file is only read.
    {"ResumedCheckpointOfAJob", "c.ckpt",
     [](const fs::path& dir, const std::string& bad) {
       app::Job j = small_job(dir, write_in(dir, "s.json", kTinyScene));
       j.resume = bad;
       j.checkpoint = (dir / "next.ckpt").string();
       return job_outcome(j);
     },
     true},
    // --resume FILE alone: the file is read and written back to.
    {"ResumeFileWrittenBackTo", "c.ckpt",
     [](const fs::path& dir, const std::string& bad) {
       app::Job j = small_job(dir, write_in(dir, "s.json", kTinyScene));
       j.resume = bad;
       return job_outcome(j);
     },
     true},
    // --checkpoint FILE that exists: resumed, then written to.
    {"ExistingCheckpointOfAJob", "c.ckpt",
     [](const fs::path& dir, const std::string& bad) {
       app::Job j = small_job(dir, write_in(dir, "s.json", kTinyScene));
       j.checkpoint = bad;
       return job_outcome(j);
     },
     true},
};

class EveryInput : public testing::TestWithParam<std::tuple<InputCase, Bad>> {
 protected:
  test::TestFolder folder_;
};

TEST_P(EveryInput, AFifoOrADirectoryIsRefusedNamingItAndSayingWhatItIs) {
  const InputCase& c = std::get<0>(GetParam());
  const Bad bad = std::get<1>(GetParam());
  test::Watchdog watchdog(kHangLimit, std::string(c.name) + (bad == Bad::Fifo ? " on a FIFO" : " on a directory"));
  const fs::path dir = folder_.root();
  const std::string bad_path = (dir / c.bad_file).string();
  if (bad == Bad::Fifo) {
    ASSERT_TRUE(make_fifo(bad_path));
  } else {
    fs::create_directory(bad_path);
  }
  const Outcome o = c.read(dir, bad_path);
  EXPECT_EQ(o.code, app::kExitBadInput) << o.message;
  EXPECT_NE(o.message.find(bad_path), std::string::npos) << "names the file: " << o.message;
  if (bad == Bad::Fifo) {
    EXPECT_NE(o.message.find("FIFO"), std::string::npos) << o.message;
  } else {
    // (The output side of a job calls a directory a folder, as its other messages do.)
    EXPECT_TRUE(o.message.find("directory") != std::string::npos || o.message.find("folder") != std::string::npos)
        << o.message;
  }
  EXPECT_EQ(o.message.find('\n'), std::string::npos) << "one line: " << o.message;
  if (c.job) {
    EXPECT_FALSE(fs::exists(dir / "out.pfm")) << "a refused job writes no image";
  }
}

INSTANTIATE_TEST_SUITE_P(, EveryInput, testing::Combine(testing::ValuesIn(kInputCases),
                                                        testing::Values(Bad::Fifo, Bad::Directory)),
                         [](const testing::TestParamInfo<EveryInput::ParamType>& info) {
                           return std::string(std::get<0>(info.param).name) +
                                  (std::get<1>(info.param) == Bad::Fifo ? "Fifo" : "Directory");
                         });

}  // namespace
}  // namespace wt
