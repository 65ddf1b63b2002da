#include "chaintube/export/batch.h"

#include "chaintube/formats/errors.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <glob.h>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

namespace chaintube::exporting {

namespace fs = std::filesystem;

std::vector<fs::path> findProjects(const std::string& folderOrPattern)
{
    std::vector<fs::path> projects;
    std::error_code error;
    if (fs::is_directory(folderOrPattern, error)) {
        fs::directory_iterator it(folderOrPattern, error);
        if (error) throw formats::FileError(folderOrPattern, error.message());
        for (const fs::directory_entry& entry : it)
            if (entry.is_regular_file() && entry.path().extension() == formats::kProjectExtension)
                projects.push_back(entry.path());
    } else {
        glob_t matches{};
        if (::glob(folderOrPattern.c_str(), 0, nullptr, &matches) == 0)
            for (size_t i = 0; i < matches.gl_pathc; ++i)
                projects.emplace_back(matches.gl_pathv[i]);
        ::globfree(&matches);
    }
    std::sort(projects.begin(), projects.end());
    return projects;
}

BatchResult exportBatch(const std::vector<fs::path>& projects, const fs::path& outputFolder,
                        const formats::NamedRoots& roots, int jobs,
                        const std::function<void(const BatchEvent&)>& onEvent,
                        const ExportOptions& options)
{
    if (jobs < 1 || jobs > 64)
        throw InvalidArgument("jobs: expected 1 … 64 parallel exports, got " +
                              std::to_string(jobs));
    const auto started = std::chrono::steady_clock::now();
    std::error_code error;
    fs::create_directories(outputFolder, error);
    if (error)
        throw formats::FileError(outputFolder,
                                 "cannot create the output folder: " + error.message());

    const std::string extension = options.container == Container::Gltf ? ".gltf" : ".glb";
    std::vector<fs::path> outputs(projects.size());
    std::vector<std::optional<std::string>> failure(projects.size());
    std::map<fs::path, size_t> firstWithOutput;
    for (size_t i = 0; i < projects.size(); ++i) {
        outputs[i] = outputFolder / (projects[i].stem().string() + extension);
        const auto [it, inserted] = firstWithOutput.emplace(outputs[i], i);
        if (!inserted)
            failure[i] = projects[i].string() + ": its output " + outputs[i].string() +
                         " is already written by " + projects[it->second].string() +
                         " (same file name in another folder)";
    }

    std::vector<std::optional<ExportReport>> reports(projects.size());
    std::atomic<size_t> next{0};
    std::mutex eventMutex;
    int finished = 0;
    ExportOptions projectOptions = options;
    projectOptions.progress = nullptr;
    projectOptions.container =
        options.container == Container::Gltf ? Container::Gltf : Container::Glb;

    const auto worker = [&] {
        for (size_t i = next++; i < projects.size(); i = next++) {
            if (!failure[i]) {
                try {
                    reports[i] = exportProjectFile(projects[i], outputs[i], roots, projectOptions);
                } catch (const std::exception& e) {
                    // chaintube errors name the file; std errors (bad_alloc, …) may not.
                    const std::string what = e.what();
                    failure[i] = what.find(projects[i].filename().string()) == std::string::npos
                                     ? projects[i].string() + ": " + what
                                     : what;
                }
            }
            const std::lock_guard<std::mutex> lock(eventMutex);
            ++finished;
            if (!onEvent) continue;
            BatchEvent event;
            event.finished = finished;
            event.total = static_cast<int>(projects.size());
            event.project = projects[i];
            event.ok = !failure[i].has_value();
            if (event.ok) {
                event.report = &*reports[i];
                event.message = outputs[i].string() + ": " + std::to_string(reports[i]->hoseCount) +
                                " hoses, " + std::to_string(reports[i]->jointCount) + " joints, " +
                                std::to_string(reports[i]->bytesWritten / 1024) + " KiB in " +
                                std::to_string(reports[i]->seconds) + " s";
            } else {
                event.message = *failure[i];
            }
            onEvent(event);
        }
    };
    const size_t threadCount =
        std::min(static_cast<size_t>(jobs), std::max<size_t>(projects.size(), 1));
    std::vector<std::thread> threads;
    for (size_t t = 1; t < threadCount; ++t)
        threads.emplace_back(worker);
    worker();
    for (std::thread& thread : threads)
        thread.join();

    BatchResult result;
    for (size_t i = 0; i < projects.size(); ++i) {
        if (failure[i])
            result.failures.push_back({projects[i], *failure[i]});
        else
            result.exported.push_back(std::move(*reports[i]));
    }
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return result;
}

} // namespace chaintube::exporting
