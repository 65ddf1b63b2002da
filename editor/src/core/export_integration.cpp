#include "chaintube/editor/export_integration.h"

#ifdef CHAINTUBE_EDITOR_HAVE_EXPORT
#include "chaintube/export/gltf_export.h"
#endif

namespace chaintube::editor {

bool exportAvailable()
{
#ifdef CHAINTUBE_EDITOR_HAVE_EXPORT
    return true;
#else
    return false;
#endif
}

ExportSummary exportProjectForEditor(const formats::Project& project,
                                     const std::filesystem::path& projectFile,
                                     const formats::NamedRoots& roots, const ExportRequest& request)
{
#ifdef CHAINTUBE_EDITOR_HAVE_EXPORT
    exporting::ExportOptions options;
    options.includeSceneMeshes = request.includeSceneMeshes;
    options.writeSidecarDescriptor = request.writeSidecarDescriptor;
    options.progress = request.progress;
    options.generator = "ChainTube Studio";
    const exporting::ExportReport report =
        exporting::exportProject(project, projectFile, request.output, roots, options);
    ExportSummary summary;
    summary.gltfFile = report.gltfFile;
    summary.binFile = report.binFile;
    summary.descriptorFile = report.descriptorFile;
    summary.hoseCount = report.hoseCount;
    summary.jointCount = report.jointCount;
    summary.sceneNodeCount = report.sceneNodeCount;
    summary.bytesWritten = report.bytesWritten;
    summary.seconds = report.seconds;
    summary.warnings = report.warnings;
    return summary;
#else
    (void)project;
    (void)projectFile;
    (void)roots;
    (void)request;
    throw Error("this build of chaintube-studio has no export library (target chaintube_export "
                "was not built)");
#endif
}

} // namespace chaintube::editor
