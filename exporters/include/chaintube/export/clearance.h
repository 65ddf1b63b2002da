// ChainTube — clearance analysis of a project: how close each hose comes
// to each scene object, and which pairs are closer than a threshold. Used by `chaintube check`
// and by the editor's problems panel (the same functions).
#pragma once

#include "chaintube/collision.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/hose.h"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace chaintube::exporting {

/// One scene object as a collider: a node that has meshes (its own meshes only, children are
/// objects of their own), at its posed world transform (project.poses applied). The node's
/// scale and shear are baked into the collider's vertices; its frame is the rigid part
/// (chaintube::rigidPart), so a pose that only moves the node can be applied with setFrame().
struct SceneObject
{
    std::string sceneId;
    int node = -1;
    std::string path; ///< SceneNode::path, e.g. "/test-rig/valve"
    std::shared_ptr<MeshCollider> collider;
};

/// A collider per node with at least one triangle, in scene and node order. `scenes` at their
/// file pose (as formats::importProjectScenes gives them). Throws InvalidArgument for a pose
/// naming an unknown scene or node.
std::vector<SceneObject> sceneObjects(const formats::Project& project,
                                      const formats::ImportedScenes& scenes);

/// Where one hose comes closest to one object.
struct ClearanceFinding
{
    int hose = -1; ///< index in project.hoses (and in the hose list given)
    std::string hoseId;
    int object = -1; ///< index in the SceneObject list given
    std::string sceneId;
    std::string objectPath;
    double distance = 0.0;        ///< hose surface to the object (metres; negative = inside)
    int axisPoint = -1;           ///< nearest axis point of the hose
    Vec3 onHose = Vec3::Zero();   ///< world point on the hose surface
    Vec3 onObject = Vec3::Zero(); ///< world point on the object
};

struct ClearanceOptions
{
    double threshold = 0.005; ///< metres ≥ 0: a pair closer than this is a violation
    /// Also check a hose against the nodes it is attached to and their ancestors (a hose end
    /// sits in its fitting by design, and the fitting in the part it belongs to: an attachment
    /// on "/rig/valve/inlet" skips "/rig/valve/inlet", "/rig/valve" and "/rig" unless asked
    /// for). Children of the attached node are objects of their own and are checked.
    bool includeAttachedNodes = false;
};

/// For every hose and every object nearer than the threshold: the minimum distance and where
/// it occurs (a violation). `hoses[i]` is the built form of `project.hoses[i]` (same order and
/// size, e.g. formats::buildHoses or the editor's live hoses). Sorted by distance, closest
/// first. Throws InvalidArgument for a negative or non-finite threshold or mismatched sizes.
std::vector<ClearanceFinding> clearanceViolations(const formats::Project& project,
                                                  const std::vector<Hose>& hoses,
                                                  const std::vector<SceneObject>& objects,
                                                  const ClearanceOptions& options);
/// Same with hoses by pointer (the editor's live hoses); a null entry (a hose that could not be
/// built) is skipped.
std::vector<ClearanceFinding> clearanceViolations(const formats::Project& project,
                                                  const std::vector<const Hose*>& hoses,
                                                  const std::vector<SceneObject>& objects,
                                                  const ClearanceOptions& options);

/// Loads the project, imports its scenes, builds its hoses (gravity hoses settled as they hang,
/// formats::settleUnderGravity: the shape the editor shows and the export writes) and returns
/// the violations (the whole of `chaintube check --clearance`). Throws the formats errors
/// (file, format, path).
std::vector<ClearanceFinding> checkProjectClearance(const std::filesystem::path& projectFile,
                                                    const formats::NamedRoots& roots,
                                                    const ClearanceOptions& options);

} // namespace chaintube::exporting
