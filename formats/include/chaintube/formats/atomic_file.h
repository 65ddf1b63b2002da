// ChainTube formats — writing a file so that a failure never damages the previous version.
#pragma once

#include <filesystem>
#include <functional>
#include <string_view>

namespace chaintube::formats {

/// Steps of writeFileAtomically(), in order; a hook may throw at any of them (tests use this
/// to simulate a full disk or a crash).
enum class AtomicWriteStep {
    TemporaryCreated, ///< the temporary file exists, nothing written yet
    HalfWritten,      ///< half of the contents are in the temporary file
    Written,          ///< all contents written, not yet flushed to disk
    Synced,           ///< fsync done, about to rename over the target
};

struct AtomicWriteOptions
{
    /// Called at every step; if it throws, the temporary file is removed, the target is left
    /// exactly as it was, and the exception propagates.
    std::function<void(AtomicWriteStep)> hook;
};

/// Replaces `target` with `contents`: writes a temporary file in the same folder, fsyncs it,
/// renames it over the target (atomic on POSIX file systems) and fsyncs the folder. On any
/// failure the temporary file is removed and the old target (if any) is untouched.
/// Throws FileError naming the target and the system's reason (e.g. "Permission denied").
void writeFileAtomically(const std::filesystem::path& target, std::string_view contents,
                         const AtomicWriteOptions& options = {});

} // namespace chaintube::formats
