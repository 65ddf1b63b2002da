// Internal to chaintube_formats: the pieces importScene() is made of.
#pragma once

#include "chaintube/formats/scene_import.h"

#include <algorithm>
#include <functional>
#include <string>

namespace chaintube::formats::detail {

/// Maps a stage's own 0…1 progress into [begin, end] of the whole import and turns a false
/// return of the caller's callback into Cancelled.
class ProgressStage
{
public:
    ProgressStage(const ImportOptions& options, const std::filesystem::path& file, double begin,
                  double end)
        : m_callback(options.progress), m_file(file), m_begin(begin), m_end(end)
    {
    }
    /// Reports fraction (0…1) of this stage; throws Cancelled if the caller asked to stop.
    void report(double fraction)
    {
        if (!m_callback) return;
        const double overall = m_begin + (m_end - m_begin) * std::clamp(fraction, 0.0, 1.0);
        if (overall < m_lastReported) return; // keep the caller's sequence non-decreasing
        m_lastReported = overall;
        if (!m_callback(overall)) throw Cancelled(m_file);
    }
    /// Same as report() but returns false instead of throwing (for C-style parser callbacks).
    bool reportNoThrow(double fraction)
    {
        if (!m_callback) return true;
        const double overall = m_begin + (m_end - m_begin) * std::clamp(fraction, 0.0, 1.0);
        if (overall < m_lastReported) return !m_cancelRequested;
        m_lastReported = overall;
        if (!m_callback(overall)) m_cancelRequested = true;
        return !m_cancelRequested;
    }
    bool cancelRequested() const { return m_cancelRequested; }
    void throwIfCancelRequested() const
    {
        if (m_cancelRequested) throw Cancelled(m_file);
    }

private:
    std::function<bool(double)> m_callback;
    std::filesystem::path m_file;
    double m_begin;
    double m_end;
    double m_lastReported = -1.0;
    bool m_cancelRequested = false;
};

/// What a reader hands over: geometry in the reader's own length unit (which is the source
/// unit for most assimp readers, but metres for readers that convert themselves: STEP, IFC,
/// COLLADA), sourceUnits describing the file as detected. Node names may be empty
/// (finaliseScene() generates them).
struct ReaderResult
{
    ImportedScene scene;
    double metresPerReaderUnit = 1.0;
    /// How many source units one reader unit is (1/f when a reader converted a unit of f metres
    /// to metres); a user's metresPerUnit override m then scales geometry by m · this.
    double sourceUnitsPerReaderUnit = 1.0;
};

/// Reads with assimp. Progress 0…1 of the stage.
ReaderResult importWithAssimp(const std::filesystem::path& file, const std::string& extension,
                              const ImportOptions& options, ProgressStage& progress);

/// Runs `reader` in a forked child process and hands back what it read (see "Process
/// isolation" in scene_import.h). The reader's progress is forwarded to `progress` as it comes;
/// a cancel from the caller kills the child and throws Cancelled. A FileError the reader throws
/// is rethrown here with its reason; a child that dies by a signal or exits without an answer
/// becomes an ImportError naming `readerName` ("PLY importer (assimp)") and the signal.
ReaderResult readInChildProcess(const std::filesystem::path& file, const std::string& readerName,
                                const ImportOptions& options, ProgressStage& progress,
                                const std::function<ReaderResult(const ImportOptions&, ProgressStage&)>& reader);

/// The human-readable name of an assimp-read format: "glTF", "COLLADA", "PLY", …
std::string assimpFormatName(const std::string& extension);

/// Reads STEP with OpenCASCADE XCAF; same contract as importWithAssimp().
ReaderResult importStep(const std::filesystem::path& file, const ImportOptions& options,
                        ProgressStage& progress);

/// Applies unit / up-axis overrides, converts to metres and +Y up, generates names for unnamed
/// nodes and assigns unique paths; returns the finished scene.
ImportedScene finaliseScene(ReaderResult&& result, const std::filesystem::path& file,
                            const ImportOptions& options);

} // namespace chaintube::formats::detail
