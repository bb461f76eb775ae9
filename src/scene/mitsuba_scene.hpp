// Mitsuba 3 scenes as wavetrace scenes: the plugin objects that mitsuba_xml reads,
// mapped onto a wavetrace scene document (docs/scene-format.md), which the JSON
// reader then reads as it reads any scene file. A scene read from XML is therefore
// the scene its JSON form describes, bit for bit, and `wavetrace convert` writes that
// JSON. The mapping, plugin by plugin, is in docs/scene-format.md ("Mitsuba 3
// scenes"); what it cannot carry over exactly is a warning of the document's
// `warnings`, or an InputError "<file>:<line>: <plugin>: <what>".
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "scene/mitsuba_xml.hpp"

namespace wt::mitsuba {

// The scene document `scene` (read from `scene.file`) means. Files it names are
// resolved against the scene file's folder, as Mitsuba resolves them, and written
// relative to it.
nlohmann::json to_wavetrace(const Object& scene);

// read_scene_xml, then to_wavetrace.
nlohmann::json read_mitsuba_scene(const std::string& path, const std::map<std::string, std::string>& defines = {});

// Whether `path` names a Mitsuba scene: its extension is .xml (any case).
bool is_mitsuba_scene(const std::string& path);

// `document`'s file paths (textures, meshes, the sky's image), written relative to
// `from` (a folder), rewritten relative to `to`, for a document written elsewhere.
void rebase_paths(nlohmann::json& document, const std::string& from, const std::string& to);

}  // namespace wt::mitsuba
