// Internal to chaintube_formats: the pieces importScene() is made of.
#pragma once

#include "chaintube/formats/scene_import.h"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

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

/// Reads with assimp. Progress 0…1 of the stage. Runs in chaintube-scene-reader.
ReaderResult importWithAssimp(const std::filesystem::path& file, const std::string& extension,
                              const ImportOptions& options, ProgressStage& progress);

/// A reader program to run: its path and its own arguments (readInChildProcess appends the
/// file and the options).
struct ReaderProgram
{
    std::filesystem::path path;
    std::vector<std::string> arguments;
};

/// Runs `program` (a program whose main calls serveAsReaderProgram) in a child process and
/// hands back what it read (see "Process isolation" in scene_import.h). The reader's progress
/// is forwarded to `progress` as it comes; a cancel from the caller kills the child and throws
/// Cancelled. A FileError the reader throws is rethrown here with its reason; a child that
/// dies by a signal or exits without an answer becomes an ImportError naming `readerName`
/// ("PLY importer (assimp)") and the signal.
ReaderResult readInChildProcess(const std::filesystem::path& file, const std::string& readerName,
                                const ImportOptions& options, ProgressStage& progress,
                                const ReaderProgram& program);

/// What a reader program reads with: its own arguments, the file, the options (with a
/// progress callback that reports to the parent if the caller gave one).
using ReaderProgramFunction = std::function<ReaderResult(
    const std::vector<std::string>& arguments, const std::filesystem::path& file,
    const ImportOptions& options, ProgressStage& progress)>;

/// A reader program's main: takes the file and options readInChildProcess put on its command
/// line, runs `reader`, answers on descriptors 3 (messages) and 4 (the scene) and ends with
/// _exit. Started by hand (wrong arguments) it says what it is and exits with status 122.
[[noreturn]] void serveAsReaderProgram(int argc, char** argv, const ReaderProgramFunction& reader);

/// The reader program `name` (chaintube-scene-reader: assimp; chaintube-step-reader:
/// OpenCASCADE): in $CHAINTUBE_READERS_DIR if set, else beside the running program, else where
/// the build made it. FileError naming `file` if there is none.
std::filesystem::path readerProgram(const std::string& name, const std::filesystem::path& file);

/// The human-readable name of an assimp-read format: "glTF", "COLLADA", "PLY", …
std::string assimpFormatName(const std::string& extension);

/// Reads STEP with OpenCASCADE XCAF; same contract as importWithAssimp(). Runs in
/// chaintube-step-reader.
ReaderResult importStep(const std::filesystem::path& file, const ImportOptions& options,
                        ProgressStage& progress);

/// Applies unit / up-axis overrides, converts to metres and +Y up, generates names for unnamed
/// nodes and assigns unique paths; returns the finished scene.
ImportedScene finaliseScene(ReaderResult&& result, const std::filesystem::path& file,
                            const ImportOptions& options);

} // namespace chaintube::formats::detail
