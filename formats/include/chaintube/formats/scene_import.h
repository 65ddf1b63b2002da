// ChainTube formats — importing CAD and DCC scenes.
#pragma once

#include "chaintube/formats/errors.h"
#include "chaintube/formats/scene.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace chaintube::formats {

struct ImportOptions
{
    /// Override the source length unit: metres per source unit (> 0, finite), e.g. 0.001 for
    /// a millimetre STL. Unset: the unit the file states, else the format's convention, else
    /// metres (see SourceUnits::unitSource).
    std::optional<double> metresPerUnit;
    /// Override the source up axis. Unset: the file's or format's, else +Y.
    std::optional<UpAxis> upAxis;
    /// STEP only: largest distance (metres, > 0) between a B-rep surface and its triangles.
    double chordalTolerance = 1e-4;
    /// STEP only: largest angle (radians, > 0) between neighbouring triangles' normals along
    /// a curved surface.
    double angularTolerance = 0.5;
    /// Called with the fraction done (0 … 1, non-decreasing) from the importing thread.
    /// Return false to cancel: importScene then throws Cancelled at once (the reader's process
    /// is killed).
    std::function<bool(double fraction)> progress;
};

/// File extensions importScene() reads, lower case with the dot: ".glb", ".stp", …
const std::vector<std::string>& supportedSceneExtensions();
/// True if the extension (case-insensitive) is one of supportedSceneExtensions().
bool isSupportedSceneFile(const std::filesystem::path& file);

/// Reads a scene file: glTF/GLB, OBJ, STL, PLY, FBX, COLLADA (.dae), 3DS, IFC, 3MF, X3D, OFF,
/// AMF through assimp (node hierarchy, names and per-node transforms kept); STEP (.stp/.step,
/// AP203/AP214) through OpenCASCADE XCAF, tessellated with options.chordalTolerance, its
/// product structure (assemblies, instances) as named nodes.
///
/// The result is in metres, +Y up, with every node path unique (see SceneNode).
/// Throws FileError naming the file and the reason for a missing, unreadable, empty,
/// truncated, malformed or unsupported file; ImportError (a FileError) if the reader crashed
/// on it; Cancelled if options.progress returned false; InvalidArgument for out-of-range
/// options.
///
/// Every import runs in a reader process (formats/README.md, "The reader processes"):
/// importScene starts `chaintube-scene-reader` (assimp) or `chaintube-step-reader`
/// (OpenCASCADE) with posix_spawn, found in $CHAINTUBE_READERS_DIR, else beside the running
/// program, else where the build put them; the calling thread waits, forwarding progress, and
/// maps the scene the reader hands back. A reader that dies by a signal or exits without an
/// answer becomes ImportError and the program goes on; a missing reader is a FileError naming
/// where it was looked for. A hanging reader is not timed out (cancel it through
/// options.progress). Thread-safe: imports from several threads run in separate readers.
/// Linux only (memfd_create, posix_spawn).
ImportedScene importScene(const std::filesystem::path& file, const ImportOptions& options = {});

} // namespace chaintube::formats
