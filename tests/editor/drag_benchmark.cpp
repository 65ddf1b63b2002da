// Responsiveness benchmark (prints figures, asserts nothing about speed): frame time while
// dragging a hose point with the 50-hose sample loaded in the engine scene, in the real main
// window under xvfb-run with Mesa's software renderer. Each frame = one mouse-move's worth of
// work: Hose::grab on the live hose, then a synchronous repaint (surface update of the dragged
// hose, upload, drawing the whole scene, glFinish).
#include "main_window.h"
#include "test_support.h"
#include "viewport.h"

#include <QApplication>
#include <QTest>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <gtest/gtest.h>
#include <numeric>

namespace chaintube::editor {
namespace {

double percentile(std::vector<double> values, double p)
{
    std::sort(values.begin(), values.end());
    return values[std::min(values.size() - 1, size_t(p * double(values.size())))];
}

TEST(DragBenchmark, FiftyHosesInTheEngineScene)
{
    if (!test::haveScenes())
        GTEST_SKIP() << "CHAINTUBE_SCENES_DIR has no 2CylinderEngine.glb: benchmark skipped";
    MainWindow window(test::roots());
    window.ask = [](const QString&, const QString&, QMessageBox::StandardButtons) {
        return QMessageBox::No;
    };
    window.resize(1280, 800);
    window.show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
    ASSERT_TRUE(window.openFile(
        QString::fromStdString((test::samplesDir() / "engine-50-hoses.ctproj").string())));
    Document& document = window.document();
    ASSERT_EQ(document.hoseCount(), 50);
    Viewport& viewport = window.viewport();
    viewport.frameAll();
    viewport.setFinishEachFrame(true);
    viewport.repaint();

    const std::string id = document.project().hoses[0].id;
    const Hose* hose = document.hose(id);
    int point = hose->pointCount() / 2;
    while (hose->isFixed(point) && point + 1 < hose->pointCount())
        ++point;
    const Vec3 start = hose->point(point);
    Selection selection;
    selection.hoseId = id;
    selection.rangeFirst = selection.rangeLast = point;
    document.setSelection(selection);

    const int frames = 200;
    std::vector<double> frameMs, grabMs, paintMs, hoseMs;
    for (int frame = 0; frame < frames; ++frame) {
        const double phase = 2.0 * M_PI * frame / 100.0;
        const Vec3 target =
            start + 0.03 * Vec3(std::sin(phase), 1.0 - std::cos(phase), 0.5 * std::sin(2 * phase));
        const auto t0 = std::chrono::steady_clock::now();
        static_cast<void>(document.dragHosePoint(id, point, target));
        const auto t1 = std::chrono::steady_clock::now();
        // Wait for the frame to be painted and composed (update() as a mouse move does).
        const long long painted = viewport.paintCount();
        viewport.update();
        while (viewport.paintCount() == painted)
            QApplication::processEvents(QEventLoop::AllEvents, 1);
        const auto t2 = std::chrono::steady_clock::now();
        hoseMs.push_back(viewport.lastRenderStats().hoseUpdateMilliseconds);
        grabMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        paintMs.push_back(viewport.lastFrameMilliseconds());
        frameMs.push_back(std::chrono::duration<double, std::milli>(t2 - t0).count());
        EXPECT_EQ(viewport.lastRenderStats().hosesDrawn, 50);
    }
    document.cancelHoseDrag(id);
    const auto mean = [](const std::vector<double>& v) {
        return std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
    };
    long long triangles = viewport.lastRenderStats().trianglesDrawn;
    std::printf("drag benchmark (engine + 50 hoses, %lld triangles, %dx%d, Xvfb + Mesa llvmpipe):\n"
                "  frame   mean %.2f ms, median %.2f ms, p95 %.2f ms (%.1f fps)\n"
                "  grab    mean %.3f ms (ChainTube deformation of the dragged hose)\n"
                "  paint   mean %.2f ms (surface update + upload + draw + glFinish)\n"
                "  hoses   mean %.3f ms of it (surface update + upload of the dragged hose)\n"
                "  multisampling: %d samples\n",
                triangles, viewport.width(), viewport.height(), mean(frameMs),
                percentile(frameMs, 0.5), percentile(frameMs, 0.95), 1000.0 / mean(frameMs),
                mean(grabMs), mean(paintMs), mean(hoseMs),
                qEnvironmentVariableIsSet("CHAINTUBE_STUDIO_SAMPLES")
                    ? qEnvironmentVariableIntValue("CHAINTUBE_STUDIO_SAMPLES")
                    : 4);
    RecordProperty("frame_ms_mean", std::to_string(mean(frameMs)));
}

} // namespace
} // namespace chaintube::editor
