#include "app/convert.hpp"

#include <cstdio>
#include <filesystem>

#include "app/job.hpp"
#include "errors/errors.hpp"
#include "image/image_io.hpp"
#include "scene/mitsuba_scene.hpp"
#include "scene/scene_file.hpp"

namespace wt::app {

int run_convert(const std::string& input, const std::string& output, const std::map<std::string, std::string>& defines) {
  namespace fs = std::filesystem;
  try {
    if (!mitsuba::is_mitsuba_scene(input)) throw InputError(input + ": convert reads a Mitsuba scene (.xml)");
    std::string ext = fs::path(output).extension().string();
    if (ext != ".json") throw OutputError(output + ": convert writes a wavetrace scene (.json)");
    check_output_folder(output);
    nlohmann::json document = mitsuba::read_mitsuba_scene(input, defines);
    // The document as the XML's folder reads it is a scene: checked by loading it.
    scene_from_document(document, input);
    const fs::path from = fs::path(input).parent_path(), to = fs::path(output).parent_path();
    mitsuba::rebase_paths(document, from.empty() ? "." : from.string(), to.empty() ? "." : to.string());
    write_file(output, document.dump(2) + "\n");
  } catch (const InputError& e) {
    std::fprintf(stderr, "wavetrace: %s\n", e.what());
    return kExitBadInput;
  } catch (const OutputWriteError& e) {  // the disk, not the input
    std::fprintf(stderr, "wavetrace: %s\n", e.what());
    return kExitFailure;
  } catch (const OutputError& e) {
    std::fprintf(stderr, "wavetrace: %s\n", e.what());
    return kExitBadInput;
  }
  return 0;
}

}  // namespace wt::app
