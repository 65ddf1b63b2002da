// ChainTube export — many projects at once (the CLI's `export --batch`, an editor's "export all").
#pragma once

#include "chaintube/export/gltf_export.h"

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace chaintube::exporting {

/// The project files a batch argument names: a folder (every *.ctproj directly in it) or a glob
/// pattern ("samples/*.ctproj", POSIX glob syntax). Sorted by path. Throws formats::FileError
/// when a folder cannot be read; an unmatched pattern gives an empty list.
std::vector<std::filesystem::path> findProjects(const std::string& folderOrPattern);

/// One project of a batch finished (successfully or not).
struct BatchEvent
{
    int finished = 0; ///< projects finished so far, including this one
    int total = 0;
    std::filesystem::path project;
    bool ok = false;
    std::string message; ///< failure: the error (names the file); success: a one-line summary
    const ExportReport* report = nullptr; ///< success only; valid during the callback
};

struct BatchFailure
{
    std::filesystem::path project;
    std::string message;
};

struct BatchResult
{
    std::vector<ExportReport> exported; ///< in project order
    std::vector<BatchFailure> failures; ///< every project that failed, in project order
    double seconds = 0.0;
    bool ok() const { return failures.empty(); }
};

/// Exports every project to outputFolder/<project file stem>.glb (or .gltf when
/// options.container is Gltf), `jobs` at a time (1 … 64; each job imports its own scenes).
/// A failing project is recorded and the batch goes on. Two projects with the same stem are a
/// failure of the second (it would overwrite the first's output). onEvent is called once per
/// project, serialised (never concurrently), from a worker thread. options.progress is ignored.
/// Throws formats::FileError if outputFolder cannot be created; InvalidArgument for jobs < 1.
BatchResult exportBatch(const std::vector<std::filesystem::path>& projects,
                        const std::filesystem::path& outputFolder, const formats::NamedRoots& roots,
                        int jobs, const std::function<void(const BatchEvent&)>& onEvent = {},
                        const ExportOptions& options = {});

} // namespace chaintube::exporting
