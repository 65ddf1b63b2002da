// A hose's fittings allowance (format 1.6, "fittingsAllowance"): metres the end fittings take up
// beyond the rest length, read as 0 when absent (older files load unchanged), written only when
// not 0, refused when negative or not a number.
#include "chaintube/formats/project.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kSamples = CHAINTUBE_SAMPLES_DIR;

json sampleDocument()
{
    return json::parse(serialiseProject(loadProject(kSamples / "test-rig.ctproj")));
}

TEST(FittingsAllowance, IsReadAsWrittenAndTakesPartInEquality)
{
    const Project project = loadProject(kSamples / "test-rig.ctproj");
    EXPECT_EQ(project.hoses[0].fittingsAllowance, 0.06);
    EXPECT_EQ(project.hoses[1].fittingsAllowance, 0.045);
    Project changed = project;
    changed.hoses[1].fittingsAllowance = 0.05;
    EXPECT_NE(changed, project);
    const Project again = parseProject(serialiseProject(changed), "again.ctproj");
    EXPECT_EQ(again, changed);
    EXPECT_EQ(again.hoses[1].fittingsAllowance, 0.05);
}

TEST(FittingsAllowance, AbsentIsZeroAndZeroIsNotWritten)
{
    json document = sampleDocument();
    document["hoses"][0].erase("fittingsAllowance");
    document["version"] = "1.5";
    const Project project = parseProject(document.dump(), "older.ctproj");
    EXPECT_EQ(project.hoses[0].fittingsAllowance, 0.0);
    const json written = json::parse(serialiseProject(project));
    EXPECT_FALSE(written["hoses"][0].contains("fittingsAllowance"));
    EXPECT_EQ(written["hoses"][1]["fittingsAllowance"], 0.045);
    EXPECT_EQ(written["version"], "1.7");
}

TEST(FittingsAllowance, NegativeOrNonNumericAllowancesAreRefusedNamingTheField)
{
    for (const json& bad : {json(-0.001), json("5 cm"), json(nullptr)}) {
        json document = sampleDocument();
        document["hoses"][1]["fittingsAllowance"] = bad;
        try {
            parseProject(document.dump(), "bad.ctproj");
            ADD_FAILURE() << "accepted " << bad.dump();
        } catch (const ProjectFormatError& error) {
            EXPECT_EQ(error.jsonPointer(), "/hoses/1/fittingsAllowance") << error.what();
            EXPECT_NE(std::string(error.what()).find("bad.ctproj"), std::string::npos);
        }
    }
}

} // namespace
} // namespace chaintube::formats
