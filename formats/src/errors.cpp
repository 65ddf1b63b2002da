#include "chaintube/formats/errors.h"

#include <utility>

namespace chaintube::formats {

FileError::FileError(std::filesystem::path file, std::string reason)
    : Error(file.string() + ": " + reason), m_file(std::move(file)), m_reason(std::move(reason))
{
}

ProjectFormatError::ProjectFormatError(std::filesystem::path file, std::string jsonPointer,
                                       std::string expected)
    : FileError(std::move(file),
                (jsonPointer.empty() ? std::string() : jsonPointer + ": ") + expected),
      m_pointer(std::move(jsonPointer)), m_expected(std::move(expected))
{
}

ImportError::ImportError(std::filesystem::path file, std::string reason, int signal, int exitStatus,
                         std::string readerOutput)
    : FileError(std::move(file), std::move(reason)), m_signal(signal), m_exitStatus(exitStatus),
      m_readerOutput(std::move(readerOutput))
{
}

Cancelled::Cancelled(const std::filesystem::path& file)
    : Error(file.string() + ": cancelled by the caller")
{
}

} // namespace chaintube::formats
