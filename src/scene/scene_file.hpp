// A scene file of either format, told apart by its extension: a Mitsuba 3 scene
// (.xml, any case: mitsuba_scene.hpp), read with its parameters, or wavetrace's JSON
// (docs/scene-format.md). load_scene(path) of scene.hpp reads either, without
// parameters.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "scene/scene.hpp"

namespace wt {

// Throws InputError naming the file (and the field, or the XML line); parameters
// given for a JSON scene are an error.
Scene load_scene(const std::string& path, const std::map<std::string, std::string>& defines);

// A scene document already parsed (a Mitsuba scene's mapping), read as its file
// `source` would be: relative paths from its folder, errors naming it.
Scene scene_from_document(nlohmann::json document, const std::string& source);

}  // namespace wt
