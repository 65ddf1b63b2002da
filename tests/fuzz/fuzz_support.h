// Shared helpers of the libFuzzer targets: a private temporary folder per process, files
// written into it, and the one place where an exception type is judged acceptable.
#pragma once

#include <chaintube/types.h>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace chaintube::fuzz {

/// A folder only this process writes to (the fuzzer may run several jobs side by side).
inline const std::filesystem::path& scratchFolder()
{
    static const std::filesystem::path folder = [] {
        std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("chaintube-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(path);
        return path;
    }();
    return folder;
}

/// Writes the fuzz input to `name` in the scratch folder and returns its path.
inline std::filesystem::path writeInput(const std::string& name, const std::uint8_t* data,
                                        std::size_t size)
{
    const std::filesystem::path file = scratchFolder() / name;
    std::ofstream(file, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return file;
}

} // namespace chaintube::fuzz
