// Test helpers shared by the test folders: a temporary folder per test, whole-file reads and
// writes, and where the samples and the third-party scenes are.
#pragma once

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <iterator>
#include <random>
#include <string>

namespace chaintube::test_support {

/// A fresh folder under the system temp folder, named after the running test, removed with
/// everything in it (also read-only files: write permission is given back first) at the end.
class TemporaryFolder
{
public:
    TemporaryFolder()
    {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::random_device random;
        m_path = std::filesystem::temp_directory_path() /
                 ("chaintube-" + std::string(info ? info->name() : "test") + "-" +
                  std::to_string(random()));
        std::filesystem::create_directories(m_path);
    }
    ~TemporaryFolder()
    {
        std::error_code ignored;
        std::filesystem::permissions(m_path, std::filesystem::perms::owner_all,
                                     std::filesystem::perm_options::add, ignored);
        std::filesystem::remove_all(m_path, ignored);
    }
    TemporaryFolder(const TemporaryFolder&) = delete;
    TemporaryFolder& operator=(const TemporaryFolder&) = delete;

    const std::filesystem::path& path() const { return m_path; }
    std::filesystem::path operator/(const std::string& name) const { return m_path / name; }

private:
    std::filesystem::path m_path;
};

/// The whole file as bytes ("" if it cannot be read).
inline std::string readText(const std::filesystem::path& file)
{
    std::ifstream stream(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

/// Replaces the file's contents with `text`, byte for byte.
inline void writeText(const std::filesystem::path& file, const std::string& text)
{
    std::ofstream stream(file, std::ios::binary);
    stream << text;
}

/// The repository's samples/ folder.
inline std::filesystem::path samplesDir()
{
    return CHAINTUBE_SAMPLES_DIR;
}
/// A sample project: samples/<name>.ctproj.
inline std::filesystem::path sampleProject(const std::string& name)
{
    return samplesDir() / (name + ".ctproj");
}
/// The third-party scenes (CHAINTUBE_SCENES_DIR); may not exist.
inline std::filesystem::path scenesDir()
{
    return CHAINTUBE_SCENES_DIR;
}
/// True if the third-party scenes are present (tests that need them skip otherwise).
inline bool haveScenes()
{
    return std::filesystem::exists(scenesDir() / "2CylinderEngine.glb");
}

} // namespace chaintube::test_support
