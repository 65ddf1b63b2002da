// ChainTube formats — the error types of file reading and writing.
//
// Error policy of formats/: everything that comes from a file is untrusted input. Problems are
// reported by throwing a subclass of chaintube::Error whose what() names the file, where in it
// (a JSON pointer for project files) and what was expected. Caller mistakes that cannot come
// from a file (e.g. a negative tolerance in ImportOptions) throw chaintube::InvalidArgument.
#pragma once

#include "chaintube/types.h"

#include <filesystem>
#include <string>

namespace chaintube::formats {

/// A file could not be read, written or understood. what() is "<file>: <reason>".
class FileError : public Error
{
public:
    FileError(std::filesystem::path file, std::string reason);
    const std::filesystem::path& file() const { return m_file; }
    /// The reason alone, without the file name.
    const std::string& reason() const { return m_reason; }

private:
    std::filesystem::path m_file;
    std::string m_reason;
};

/// A project document is malformed. what() is "<file>: <JSON pointer>: <what was expected>",
/// e.g. "engine.ctproj: /hoses/2/material/expansionCoefficient: expected a number in [0, 1),
/// got 1.5". The pointer is "" for the whole document.
class ProjectFormatError : public FileError
{
public:
    ProjectFormatError(std::filesystem::path file, std::string jsonPointer, std::string expected);
    const std::string& jsonPointer() const { return m_pointer; }
    const std::string& expected() const { return m_expected; }

private:
    std::string m_pointer;
    std::string m_expected;
};

/// The third-party reader of a scene file did not come back: its process was ended by a signal
/// (it crashed, e.g. an assertion inside assimp aborted on malformed data) or exited without an
/// answer. importScene() runs every reader in a process of its own so that this is an error and
/// not the end of the program. what() is "<file>: the <format> importer crashed on malformed data
/// (signal 6, SIGABRT: Aborted); it wrote: <its last line>".
class ImportError : public FileError
{
public:
    ImportError(std::filesystem::path file, std::string reason, int signal, int exitStatus,
                std::string readerOutput);
    /// The signal that ended the reader's process, 0 if it was not ended by a signal.
    int signal() const { return m_signal; }
    /// The reader process's exit status when it exited without an answer, −1 otherwise.
    int exitStatus() const { return m_exitStatus; }
    /// What the reader process wrote to stderr and stdout (its first 64 KiB), e.g. assimp's
    /// "ai_assert failure in …" or a sanitizer report.
    const std::string& readerOutput() const { return m_readerOutput; }

private:
    int m_signal;
    int m_exitStatus;
    std::string m_readerOutput;
};

/// The caller's progress callback asked to stop. Nothing was returned; no state was changed.
class Cancelled : public Error
{
public:
    explicit Cancelled(const std::filesystem::path& file);
};

} // namespace chaintube::formats
