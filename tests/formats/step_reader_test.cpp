// STEP through chaintube-step-reader (OpenCASCADE in a process of its own) on files this test
// writes with OpenCASCADE, so that it runs without the third-party scenes.
#include <BRepPrimAPI_MakeBox.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Writer.hxx>
#include <TopoDS_Shape.hxx>
#include <chaintube/formats/scene_import.h>
#include <filesystem>
#include <gtest/gtest.h>
#include <random>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;

class StepReader : public ::testing::Test
{
protected:
    void SetUp() override
    {
        m_folder = fs::temp_directory_path() /
                   ("chaintube-step-" + std::to_string(std::random_device{}()));
        fs::create_directories(m_folder);
    }
    void TearDown() override { fs::remove_all(m_folder); }

    /// A STEP file with one box of dx × dy × dz millimetres.
    fs::path writeBox(const std::string& name, double dx, double dy, double dz)
    {
        const TopoDS_Shape box = BRepPrimAPI_MakeBox(dx, dy, dz).Shape();
        Interface_Static::SetCVal("write.step.unit", "MM");
        STEPControl_Writer writer;
        EXPECT_EQ(writer.Transfer(box, STEPControl_AsIs), IFSelect_RetDone);
        const fs::path file = m_folder / name;
        EXPECT_EQ(writer.Write(file.c_str()), IFSelect_RetDone);
        return file;
    }

    fs::path m_folder;
};

TEST_F(StepReader, ABoxComesBackInMetresYUp)
{
    const fs::path file = writeBox("box.step", 100.0, 20.0, 10.0);
    std::vector<double> reports;
    ImportOptions options;
    options.progress = [&](double fraction) {
        reports.push_back(fraction);
        return true;
    };
    const ImportedScene scene = importScene(file, options);
    EXPECT_EQ(scene.format, "STEP");
    EXPECT_EQ(scene.sourceUnits.unitSource, UnitSource::FileHeader);
    EXPECT_DOUBLE_EQ(scene.sourceUnits.metresPerUnit, 0.001);
    ASSERT_EQ(scene.meshes.size(), 1u);
    EXPECT_EQ(scene.meshTriangleCount(), 12u); // 6 planar faces, 2 triangles each
    // Bounds of the instanced mesh in metres: STEP's +Z up becomes +Y up.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (size_t n = 0; n < scene.nodes.size(); ++n) {
        const Mat4 world = scene.worldTransform(static_cast<int>(n));
        for (const int m : scene.nodes[n].meshes) {
            const std::vector<float>& p = scene.meshes[static_cast<size_t>(m)].positions;
            for (size_t k = 0; k + 2 < p.size(); k += 3) {
                const Eigen::Vector4d at = world * Eigen::Vector4d(p[k], p[k + 1], p[k + 2], 1.0);
                lo = lo.cwiseMin(at.head<3>());
                hi = hi.cwiseMax(at.head<3>());
            }
        }
    }
    const Eigen::Vector3d size = hi - lo;
    EXPECT_NEAR(size.x(), 0.100, 1e-6);
    EXPECT_NEAR(size.y(), 0.010, 1e-6); // the box's z
    EXPECT_NEAR(size.z(), 0.020, 1e-6); // the box's y
    ASSERT_FALSE(reports.empty());
    EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
    EXPECT_EQ(reports.back(), 1.0);
}

TEST_F(StepReader, ACancelEndsTheReader)
{
    const fs::path file = writeBox("box.step", 1.0, 2.0, 3.0);
    ImportOptions options;
    options.progress = [](double fraction) { return fraction < 0.1; };
    EXPECT_THROW(importScene(file, options), Cancelled);
}

TEST_F(StepReader, AMissingReaderProgramIsAClearError)
{
    const fs::path file = writeBox("box.step", 1.0, 2.0, 3.0);
    ::setenv("CHAINTUBE_READERS_DIR", m_folder.c_str(), 1);
    try {
        static_cast<void>(importScene(file));
        ADD_FAILURE() << "no error";
    } catch (const FileError& error) {
        EXPECT_EQ(std::string(error.what()),
                  file.string() +
                      ": cannot start the importer process: CHAINTUBE_READERS_DIR is '" +
                      m_folder.string() + "', which holds no executable chaintube-step-reader");
    }
    ::unsetenv("CHAINTUBE_READERS_DIR");
}

} // namespace
} // namespace chaintube::formats
