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
/// Process isolation. assimp 5.2.5 as Debian ships it aborts the whole program on some
/// malformed files (an ai_assert in TriangulateProcess on a PLY face without indices; no
/// importer flag or property catches it: aiProcess_ValidateDataStructure and FindDegenerates /
/// FindInvalidData were tried), and its readers have had crashes before. So every import runs
/// in a process of its own: importScene starts a reader program with posix_spawn,
/// `chaintube-scene-reader` (assimp) or `chaintube-step-reader` (OpenCASCADE, STEP), built in
/// formats/ and found in $CHAINTUBE_READERS_DIR, else beside the running program, else where
/// the build put them. The reader reads and converts, hands the result (meshes, nodes, units)
/// back and ends; the caller's thread waits for it, forwarding progress
/// messages to options.progress as they come. A reader that dies by a signal becomes
/// ImportError ("the PLY importer (assimp) crashed on malformed data (signal 6, SIGABRT:
/// Aborted); it wrote: ai_assert failure …"); the program goes on. The scene travels through a
/// memory file (memfd) the caller maps, not the pipe. A missing reader program is a FileError
/// that says where it was looked for. Linux only (memfd_create, posix_spawn's closefrom).
///
/// Why a fresh program and not fork() alone: the caller may have other threads (the Qt editor
/// imports on a worker), and a forked copy of a multithreaded process may only run
/// async-signal-safe code until it execs: a lock another thread held at the moment of the fork
/// stays held in the copy. With glibc's malloc that happened to work; under AddressSanitizer
/// (GCC 12's runtime has no fork handlers) a forked reader hung for good in CI when four threads
/// imported at once. The reader gets the crash signals at their default actions (so a crash
/// ends it by its signal, also when built with a sanitizer), only its own descriptors, stdin
/// from /dev/null, and is killed if the caller's thread dies (PR_SET_PDEATHSIG). The caller's
/// progress callback is never called in it. A reader that hangs is not timed out (the caller
/// can cancel it).
/// Cost: about 0.5 ms an import for the assimp reader (2CylinderEngine.glb: 20.2 against 19.9 ms
/// median with the earlier fork); the STEP reader loads OpenCASCADE's libraries at each start
/// (36 ms), so a STEP import costs ~60 ms more than in the caller's process (as1-oc-214.stp:
/// ~270 against ~210 ms, measured under load), for isolation from OpenCASCADE's crashes and
/// its memory handed back after each import.
ImportedScene importScene(const std::filesystem::path& file, const ImportOptions& options = {});

} // namespace chaintube::formats
