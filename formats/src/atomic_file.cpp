#include "chaintube/formats/atomic_file.h"

#include "chaintube/formats/errors.h"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

namespace chaintube::formats {

namespace fs = std::filesystem;

namespace {

std::string systemReason(const char* what)
{
    return std::string(what) + ": " + std::strerror(errno);
}

/// Removes the temporary file unless released (i.e. renamed into place).
class TemporaryFile
{
public:
    TemporaryFile(const fs::path& target) : m_path(target)
    {
        // Same folder as the target, so the final rename never crosses file systems.
        std::string pattern =
            (target.parent_path() / ("." + target.filename().string() + ".tmp-XXXXXX")).string();
        m_descriptor = ::mkstemp(pattern.data());
        if (m_descriptor < 0)
            throw FileError(target, systemReason("cannot create a temporary file next to it"));
        m_path = pattern;
        ::fchmod(m_descriptor, 0644); // mkstemp makes 0600; a project is an ordinary document
    }
    ~TemporaryFile()
    {
        closeDescriptor();
        if (!m_released) ::unlink(m_path.c_str());
    }
    TemporaryFile(const TemporaryFile&) = delete;
    TemporaryFile& operator=(const TemporaryFile&) = delete;

    int descriptor() const { return m_descriptor; }
    const fs::path& path() const { return m_path; }
    void closeDescriptor()
    {
        if (m_descriptor >= 0) ::close(m_descriptor);
        m_descriptor = -1;
    }
    void release() { m_released = true; }

private:
    fs::path m_path;
    int m_descriptor = -1;
    bool m_released = false;
};

void writeAll(int descriptor, const char* data, size_t size, const fs::path& target)
{
    while (size > 0) {
        const ssize_t written = ::write(descriptor, data, size);
        if (written < 0) {
            if (errno == EINTR) continue;
            throw FileError(target, systemReason("writing the temporary file failed"));
        }
        data += written;
        size -= static_cast<size_t>(written);
    }
}

} // namespace

void writeFileAtomically(const fs::path& target, std::string_view contents,
                         const AtomicWriteOptions& options)
{
    const auto step = [&](AtomicWriteStep s) {
        if (options.hook) options.hook(s);
    };
    fs::path folder = target.parent_path();
    if (folder.empty()) folder = ".";
    std::error_code error;
    if (fs::is_directory(target, error))
        throw FileError(target, "is a directory; cannot replace it with a file");

    TemporaryFile temporary(folder / target.filename());
    step(AtomicWriteStep::TemporaryCreated);
    const size_t half = contents.size() / 2;
    writeAll(temporary.descriptor(), contents.data(), half, target);
    step(AtomicWriteStep::HalfWritten);
    writeAll(temporary.descriptor(), contents.data() + half, contents.size() - half, target);
    step(AtomicWriteStep::Written);
    if (::fsync(temporary.descriptor()) != 0)
        throw FileError(target, systemReason("fsync of the temporary file failed"));
    step(AtomicWriteStep::Synced);
    temporary.closeDescriptor();
    if (::rename(temporary.path().c_str(), target.c_str()) != 0)
        throw FileError(target, systemReason("renaming the temporary file over it failed"));
    temporary.release();

    // Make the rename itself durable. Failing here cannot damage either version of the file.
    const int folderDescriptor = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
    if (folderDescriptor >= 0) {
        ::fsync(folderDescriptor);
        ::close(folderDescriptor);
    }
}

} // namespace chaintube::formats
