// ChainTube editor — the one place where the editor calls the glTF exporter.
//
// The Export dialog calls exportProjectForEditor(), which calls exactly the library function
// the `chaintube` CLI calls (chaintube::exporting::exportProject in
// exporters/include/chaintube/export/gltf_export.h). When the editor is built without the
// export library (target chaintube_export absent), exportAvailable() is false and the call
// throws; nothing is faked.
#pragma once

#include "chaintube/formats/project.h"

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace chaintube::editor {

struct ExportRequest
{
    std::filesystem::path output; ///< .glb or .gltf; empty: the project's export settings
    bool includeSceneMeshes = true;
    bool writeSidecarDescriptor = true;
    /// Fraction done 0 … 1 (called on the exporting thread); return false to cancel.
    std::function<bool(double)> progress;
};

/// What an export wrote (copied from the exporter's report).
struct ExportSummary
{
    std::filesystem::path gltfFile, binFile, descriptorFile;
    int hoseCount = 0;
    int jointCount = 0;
    int sceneNodeCount = 0;
    std::size_t bytesWritten = 0;
    double seconds = 0.0;
    std::vector<std::string> warnings;
};

/// True if the editor was built with the export library.
bool exportAvailable();

/// Exports the project (saved or not; relative paths resolve against projectFile's folder).
/// Throws what the exporter throws (formats::Cancelled when progress returned false), or
/// chaintube::Error when the export library is not built in.
ExportSummary exportProjectForEditor(const formats::Project& project,
                                     const std::filesystem::path& projectFile,
                                     const formats::NamedRoots& roots,
                                     const ExportRequest& request);

} // namespace chaintube::editor
