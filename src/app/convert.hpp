// `wavetrace convert`: a Mitsuba 3 scene (.xml) written as the wavetrace scene
// document it is read as (scene/mitsuba_scene.hpp), the files it names referenced
// where they are (relative to the output's folder), not copied.
#pragma once

#include <map>
#include <string>

namespace wt::app {

// Reads `input` with `defines`, checks that the document loads as a scene, and
// writes it to `output` (atomically). Returns the exit code: 0, or kExitBadInput
// with one line on stderr (a bad scene, an output that cannot be written).
int run_convert(const std::string& input, const std::string& output, const std::map<std::string, std::string>& defines);

}  // namespace wt::app
