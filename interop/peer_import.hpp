// `flatmarch import-peer`: converts a geometry of the original web app (Lander & Taha's
// RayMarchingFlatSurfaces; format in tests/data/peer-geometries/README.md) into our scene
// format, and checks the fields that file states but our scenes derive (normals, translation
// vectors, affine maps) against the maps our loader derives.
//
// The app is three.js with y up and the floor plan in (x, z); its walls span y in
// [-wallHeight, wallHeight]. A point (x, y, z) of the app is (x, z, y + wallHeight) here, in the
// scene's only polygon, whose height is 2 wallHeight. The floor plan keeps its coordinates (the
// app's image is therefore the mirror image of ours), a clockwise polygon is reversed.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/scene.hpp"

namespace flatmarch {

enum class Severity {
  disagrees,  // a redundant field of the file disagrees with what our loader derives
  converted,  // converted, but not one to one (say how)
  moved,      // moved so that it fits our rules
  dropped,    // cannot be converted: left out
  ignored,    // a field our scenes have no use for
};

const char* to_string(Severity severity);

struct PeerFinding {
  std::string pointer;  // JSON pointer into the peer file ("/" for the document)
  Severity severity = Severity::converted;
  std::string message;
};

struct PeerImport {
  nlohmann::ordered_json scene;  // a valid scene: scene_from_json accepts it
  std::vector<PeerFinding> findings;
};

// A malformed peer file throws SceneError with the JSON pointer into the peer file. `file`
// names the source in errors and findings; its stem, in snake case, names the scene.
PeerImport import_peer(const nlohmann::json& peer, const std::string& file);
// import_peer of a file; the scene says where it came from ("imported_from", the file's absolute
// path), for an external renderer that reads the app's format (docs/external.md).
PeerImport import_peer_file(const std::filesystem::path& path);

// Whether a JSON document is a geometry of the app rather than a scene of ours (it has the app's
// "vertices" and "gluing", not our "polygons").
bool is_peer_geometry(const nlohmann::json& doc);

// Turns an imported scene's camera to the view the benchmarks take of the app
// (../shared/peer-shaders.md): from the app's start point + (0.5, 0, 0.5), looking along
// normalize(1, 0, 0.3), level, which is here the start moved by (0.5, 0.5, 0) and turned to yaw
// atan2(0.3, 1). The field of view stays the app's. (Our image is the app's mirrored left to
// right: the same rays.)
Camera benchmark_view(Camera start);
// The same, on an imported scene's JSON.
void use_benchmark_view(nlohmann::ordered_json& scene);

nlohmann::ordered_json findings_json(const std::vector<PeerFinding>& findings);

}  // namespace flatmarch
