// writeFileAtomically(): a failure at any step leaves the previous file intact.
#include "chaintube/formats/atomic_file.h"
#include "chaintube/formats/errors.h"
#include "test_files.h"

#include <gtest/gtest.h>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using testing::TemporaryFolder;

size_t fileCount(const fs::path& folder)
{
    return static_cast<size_t>(
        std::distance(fs::directory_iterator(folder), fs::directory_iterator()));
}

TEST(AtomicWrite, ReplacesTheFileContents)
{
    TemporaryFolder folder;
    testing::writeText(folder / "a.ctproj", "old");
    writeFileAtomically(folder / "a.ctproj", "new contents");
    EXPECT_EQ(testing::readText(folder / "a.ctproj"), "new contents");
    EXPECT_EQ(fileCount(folder.path()), 1u) << "no temporary file is left behind";
}

class FailureAtStep : public ::testing::TestWithParam<AtomicWriteStep>
{
};

TEST_P(FailureAtStep, LeavesTheOldFileIntactAndNoTemporaryFile)
{
    TemporaryFolder folder;
    testing::writeText(folder / "a.ctproj", "the previous version");
    AtomicWriteOptions options;
    options.hook = [](AtomicWriteStep step) {
        if (step == GetParam()) throw std::runtime_error("simulated disk failure");
    };
    EXPECT_THROW(writeFileAtomically(folder / "a.ctproj", std::string(100000, 'x'), options),
                 std::runtime_error);
    EXPECT_EQ(testing::readText(folder / "a.ctproj"), "the previous version");
    EXPECT_EQ(fileCount(folder.path()), 1u);
}

INSTANTIATE_TEST_SUITE_P(EveryStep, FailureAtStep,
                         ::testing::Values(AtomicWriteStep::TemporaryCreated,
                                           AtomicWriteStep::HalfWritten, AtomicWriteStep::Written,
                                           AtomicWriteStep::Synced));

TEST(AtomicWrite, MissingFolderIsAFileErrorNamingTheTarget)
{
    TemporaryFolder folder;
    try {
        writeFileAtomically(folder / "no/such/folder/a.ctproj", "x");
        FAIL() << "no FileError";
    } catch (const FileError& error) {
        EXPECT_EQ(error.file(), folder / "no/such/folder/a.ctproj");
        EXPECT_NE(error.reason().find("No such file or directory"), std::string::npos)
            << error.what();
    }
}

TEST(AtomicWrite, TargetThatIsADirectoryIsRefusedAndUntouched)
{
    TemporaryFolder folder;
    fs::create_directory(folder / "a.ctproj");
    testing::writeText(folder / "a.ctproj/keep", "k");
    EXPECT_THROW(writeFileAtomically(folder / "a.ctproj", "x"), FileError);
    EXPECT_EQ(testing::readText(folder / "a.ctproj/keep"), "k");
}

} // namespace
} // namespace chaintube::formats
