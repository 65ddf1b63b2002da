// The main window tests' fixture: the window with its prompts answered No unless a test says
// otherwise, and the gestures that lay out routes on the test rig's floor and on the STEP
// bracket assembly.
#pragma once

#include "chaintube/formats/scene.h"
#include "window_test.h"

#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <algorithm>
#include <cmath>
#include <filesystem>

namespace chaintube::editor::test {

namespace fs = std::filesystem;

/// The L-bracket the route tests on the STEP assembly click on.
inline const std::string kStepBracket = "/as1/l-bracket-assembly_1/l-bracket_1";

/// A project in a fresh output folder with the test rig's material presets, no hose and the
/// one scene `scene` (a "scenes" entry; a relative "path" names a copy of the test rig's
/// scene file). Returns the project file.
inline QString writeProject(const std::string& folderName, const QJsonObject& scene)
{
    const fs::path folder = outputDir() / folderName;
    fs::remove_all(folder);
    fs::create_directories(folder / "scenes");
    fs::copy_file(samplesDir() / "scenes/test-rig.gltf", folder / "scenes/test-rig.gltf");
    QFile rig(QString::fromStdString((samplesDir() / "test-rig.ctproj").string()));
    EXPECT_TRUE(rig.open(QIODevice::ReadOnly));
    QJsonObject project = QJsonDocument::fromJson(rig.readAll()).object();
    project["name"] = QString::fromStdString(folderName);
    project["scenes"] = QJsonArray{scene};
    project["hoses"] = QJsonArray();
    project.remove("poses");
    project.remove("sockets"); // on the rig's parts, which this project does not have
    const QString file = QString::fromStdString((folder / "project.ctproj").string());
    QFile out(file);
    EXPECT_TRUE(out.open(QIODevice::WriteOnly));
    out.write(QJsonDocument(project).toJson());
    return file;
}

/// Checks a GLB's container and JSON; returns the JSON.
inline QJsonObject readGlb(const fs::path& file)
{
    QFile in(QString::fromStdString(file.string()));
    EXPECT_TRUE(in.open(QIODevice::ReadOnly)) << file;
    const QByteArray bytes = in.readAll();
    EXPECT_GE(bytes.size(), 20);
    if (bytes.size() < 20) return {};
    auto u32 = [&](int offset) {
        return quint32(quint8(bytes[offset])) | quint32(quint8(bytes[offset + 1])) << 8 |
               quint32(quint8(bytes[offset + 2])) << 16 | quint32(quint8(bytes[offset + 3])) << 24;
    };
    EXPECT_EQ(bytes.left(4), QByteArray("glTF"));
    EXPECT_EQ(u32(4), 2u);
    EXPECT_EQ(u32(8), quint32(bytes.size()));
    const quint32 jsonLength = u32(12);
    EXPECT_EQ(u32(16), 0x4E4F534Au); // "JSON"
    QJsonParseError error;
    const QJsonDocument json = QJsonDocument::fromJson(bytes.mid(20, int(jsonLength)), &error);
    EXPECT_EQ(error.error, QJsonParseError::NoError) << error.errorString().toStdString();
    return json.object();
}

class MainWindowTest : public WindowTest
{
protected:
    MainWindowTest() { m_answer = QMessageBox::No; }
    void SetUp() override { m_window = makeWindow(); }
    /// Screen positions (8 px grid) whose pick hits node `path` from above (normal up).
    std::vector<std::pair<QPoint, ScenePickHit>> topHits(const std::string& path)
    {
        std::vector<std::pair<QPoint, ScenePickHit>> hits;
        Viewport& viewport = m_window->viewport();
        for (int y = 4; y < viewport.height(); y += 8)
            for (int x = 4; x < viewport.width(); x += 8) {
                ScenePickHit hit;
                if (viewport.pickScene(QPointF(x, y), &hit) && hit.normal.y() > 0.9 &&
                    m_window->document().scene(hit.sceneId)->nodes[size_t(hit.node)].path == path)
                    hits.push_back({QPoint(x, y), hit});
            }
        return hits;
    }
    /// Opens the STEP bracket assembly (as1-oc-214.stp of the scenes folder) as the one scene of
    /// a new project in `folderName`, frames it (Home) and starts a new hose (N); `bracket`
    /// receives the collider of kStepBracket at its pose. Skips the test where the scene is
    /// absent: check IsSkipped() and HasFatalFailure() after the call.
    void openStepBracketToLayARoute(const std::string& folderName,
                                    std::shared_ptr<MeshCollider>* bracket)
    {
        if (!fs::exists(scenesDir() / "as1-oc-214.stp"))
            GTEST_SKIP() << "CHAINTUBE_SCENES_DIR has no as1-oc-214.stp: STEP bracket test skipped";
        const QJsonObject scene{
            {"id", "as1"},
            {"path", "scenes:as1-oc-214.stp"},
            {"import", QJsonObject{{"chordalTolerance", 1e-4}, {"angularTolerance", 0.5}}}};
        ASSERT_TRUE(m_window->openFile(writeProject(folderName, scene)))
            << m_errors.join('\n').toStdString();
        // The import's progress dialog had the focus: the window takes the keys again.
        m_window->activateWindow();
        QApplication::setActiveWindow(m_window.get());
        QTest::keyClick(&m_window->viewport(), Qt::Key_Home);
        settle();
        QTest::keyClick(&m_window->viewport(), Qt::Key_N);
        ASSERT_EQ(m_window->viewport().mode(), Viewport::Mode::LayRoute);
        const Document& document = m_window->document();
        const formats::ImportedScene& as1 = *document.scene("as1");
        const int node = as1.findNode(kStepBracket);
        ASSERT_GE(node, 0);
        *bracket = formats::nodeCollider(as1, node, document.nodeWorldTransform("as1", node));
        ASSERT_TRUE(*bracket);
    }
    /// Lays out a new hose by clicks on the floor plate nearest (in x and z) each of `spots`
    /// (N, the clicks, Enter); returns the route points as the clicks placed them.
    std::vector<Vec3> layRouteOnTheFloor(const std::vector<Vec3>& spots)
    {
        Viewport& viewport = m_window->viewport();
        const auto floor = topHits("/test-rig/floor_plate");
        EXPECT_FALSE(floor.empty());
        if (floor.empty()) return {};
        QTest::keyClick(&viewport, Qt::Key_N);
        for (const Vec3& spot : spots) {
            auto d = [&](const Vec3& p) { return std::hypot(p.x() - spot.x(), p.z() - spot.z()); };
            const auto nearest =
                std::min_element(floor.begin(), floor.end(), [&](const auto& a, const auto& b) {
                    return d(a.second.point) < d(b.second.point);
                });
            QTest::mouseClick(&viewport, Qt::LeftButton, {}, nearest->first);
        }
        const std::vector<Vec3> clicked = viewport.pendingRoute();
        EXPECT_EQ(clicked.size(), spots.size());
        takeKeys();
        QTest::keyClick(&viewport, Qt::Key_Return);
        settle();
        return clicked;
    }
};

} // namespace chaintube::editor::test
