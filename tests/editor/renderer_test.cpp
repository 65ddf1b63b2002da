// Renderer images, offscreen (QOffscreenSurface + QOpenGLFramebufferObject) under xvfb-run
// with Mesa: compared against reference PNGs in tests/editor/data with a tolerance, and
// checked for a hose drawn where it is expected. CHAINTUBE_UPDATE_REFERENCES=1 rewrites the
// references.
#include "chaintube/editor/commands.h"
#include "chaintube/editor/renderer.h"
#include "test_support.h"

#include <QImage>
#include <QOffscreenSurface>
#include <QOpenGLContext>
#include <QOpenGLFramebufferObject>
#include <cstdlib>
#include <gtest/gtest.h>
#include <memory>

namespace chaintube::editor {
namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;

class RendererTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        QSurfaceFormat format;
        format.setVersion(3, 3);
        format.setProfile(QSurfaceFormat::CoreProfile);
        format.setDepthBufferSize(24);
        m_context.setFormat(format);
        ASSERT_TRUE(m_context.create()) << "no OpenGL context (is DISPLAY an Xvfb?)";
        m_surface.setFormat(m_context.format());
        m_surface.create();
        ASSERT_TRUE(m_context.makeCurrent(&m_surface));
        QOpenGLFramebufferObjectFormat fboFormat;
        fboFormat.setAttachment(QOpenGLFramebufferObject::Depth);
        m_fbo = std::make_unique<QOpenGLFramebufferObject>(kWidth, kHeight, fboFormat);
        ASSERT_TRUE(m_fbo->isValid());
        ASSERT_TRUE(m_renderer.initialize()) << m_renderer.errorString();
        m_document.adopt(readProject(test::samplesDir() / "test-rig.ctproj", test::roots()));
        // A fixed camera looking at the rig from the front, slightly above.
        m_camera.target = Vec3(0.0, 0.15, 0.0);
        m_camera.distance = 1.3;
        m_camera.yaw = 0.0;
        m_camera.pitch = -0.35;
    }
    void TearDown() override
    {
        if (m_context.isValid() && m_context.makeCurrent(&m_surface)) {
            m_renderer.releaseResources();
            m_fbo.reset();
            m_context.doneCurrent();
        }
    }
    QImage render(const RenderOptions& options = {})
    {
        m_fbo->bind();
        m_renderer.render(m_document, m_camera, kWidth, kHeight, options);
        m_fbo->release();
        return m_fbo->toImage().convertToFormat(QImage::Format_RGB32);
    }
    QPoint pixelOf(const Vec3& world) const
    {
        Eigen::Vector2d p;
        EXPECT_TRUE(m_camera.project(world, kWidth, kHeight, &p));
        return QPoint(int(p.x()), int(p.y()));
    }

    QOpenGLContext m_context;
    QOffscreenSurface m_surface;
    std::unique_ptr<QOpenGLFramebufferObject> m_fbo;
    Renderer m_renderer;
    Document m_document{test::roots()};
    Camera m_camera;
};

/// Fraction of pixels whose largest channel difference exceeds `threshold`.
double differingFraction(const QImage& a, const QImage& b, int threshold)
{
    if (a.size() != b.size()) return 1.0;
    long long differing = 0;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x) {
            const QRgb p = a.pixel(x, y), q = b.pixel(x, y);
            const int d = std::max({std::abs(qRed(p) - qRed(q)), std::abs(qGreen(p) - qGreen(q)),
                                    std::abs(qBlue(p) - qBlue(q))});
            differing += d > threshold;
        }
    return double(differing) / (a.width() * a.height());
}

void compareWithReference(const QImage& image, const char* name)
{
    const QString reference = QString(CHAINTUBE_TEST_DATA_DIR) + "/" + name;
    const QString actual = QString::fromStdString((test::outputDir() / name).string());
    image.save(actual);
    if (std::getenv("CHAINTUBE_UPDATE_REFERENCES")) {
        image.save(reference);
        GTEST_SKIP() << "reference rewritten: " << reference.toStdString();
    }
    QImage expected(reference);
    ASSERT_FALSE(expected.isNull()) << "missing reference " << reference.toStdString()
                                    << " (run with CHAINTUBE_UPDATE_REFERENCES=1)";
    expected = expected.convertToFormat(QImage::Format_RGB32);
    // Tolerance: Mesa versions differ in rasterisation details; at most 1 % of the pixels may
    // differ by more than 24 levels in a channel.
    EXPECT_LT(differingFraction(image, expected, 24), 0.01)
        << "compare " << actual.toStdString() << " with " << reference.toStdString();
}

TEST_F(RendererTest, ShadedTestRigMatchesTheReference)
{
    compareWithReference(render(), "test-rig-shaded.png");
}

TEST_F(RendererTest, WireframeTestRigMatchesTheReference)
{
    RenderOptions options;
    options.wireframe = true;
    const QImage wire = render(options);
    EXPECT_GT(differingFraction(wire, render(), 24), 0.05) << "wireframe looks like shaded";
    compareWithReference(wire, "test-rig-wireframe.png");
}

TEST_F(RendererTest, AHoseIsDrawnAlongItsAxisInItsColour)
{
    const QImage before = render();
    // A red hose across the front of the rig, away from the scene geometry.
    formats::HoseDefinition definition;
    definition.id = "red";
    definition.route = {Vec3(-0.3, 0.45, 0.25), Vec3(0.3, 0.45, 0.25)};
    definition.outerDiameter = 0.03;
    definition.colour = {1.0, 0.0, 0.0, 1.0};
    m_document.undoStack()->push(new AddHoseCommand(m_document, definition));
    const QImage after = render();
    for (double s : {0.2, 0.5, 0.8}) {
        const QPoint pixel = pixelOf(Vec3(-0.3 + 0.6 * s, 0.45, 0.25));
        const QRgb colour = after.pixel(pixel);
        EXPECT_GT(qRed(colour), 2 * qGreen(colour) + 20) << "at " << s;
        EXPECT_GT(qRed(colour), 2 * qBlue(colour) + 20) << "at " << s;
        EXPECT_NE(before.pixel(pixel), colour);
    }
    // Well above the hose nothing changed.
    const QPoint above = pixelOf(Vec3(0.0, 0.6, 0.25));
    EXPECT_EQ(before.pixel(above), after.pixel(above));
}

TEST_F(RendererTest, APartPulledBeyondReachLeavesTheHoseInItsBandAndDrawsTheGapInProblemRed)
{
    // Pull the valve away: the right hose (fixed to it and to the bracket) cannot reach it. It
    // goes taut with every segment in its band, and the attachment it cannot meet is drawn: a
    // problem-red line from the hose to where the valve wants it, a dot at that spot.
    const int valve = m_document.scene("rig")->findNode("/test-rig/valve");
    formats::Mat4 moved = m_document.nodeLocalTransform("rig", valve);
    moved(0, 3) -= 0.6;
    moved(2, 3) += 0.4;
    m_document.undoStack()->push(makeSetNodeTransform(m_document, {"rig", valve}, moved));
    const std::string id = "right-return";
    const HoseMetrics& metrics = *m_document.hoseMetrics(id);
    EXPECT_FALSE(metrics.overstretched());
    ASSERT_FALSE(metrics.unmetAttachments.empty());
    EXPECT_GT(metrics.unmetAttachments.front().gap, 0.05);
    const Hose& hose = *m_document.hose(id);
    for (int s = 0; s < hose.segmentCount(); ++s)
        EXPECT_LE((hose.point(s + 1) - hose.point(s)).norm(), hose.maxLength(s) * (1 + 1e-9)) << s;
    const Hose::Attachment* unmet = nullptr;
    for (const Hose::Attachment& attachment : hose.attachments())
        if (attachment.id == metrics.unmetAttachments.front().id) unmet = &attachment;
    ASSERT_NE(unmet, nullptr);
    m_camera.target = unmet->frame.apply(unmet->localPoints.front()); // where the valve wants it
    m_camera.distance = 0.25;
    RenderOptions options;
    const QRgb highlighted = render(options).pixel(kWidth / 2, kHeight / 2);
    options.showProblems = false;
    const QRgb plain = render(options).pixel(kWidth / 2, kHeight / 2);
    EXPECT_GT(qRed(highlighted), qGreen(highlighted) + 60);
    EXPECT_GT(qRed(highlighted), qBlue(highlighted) + 60);
    EXPECT_NE(highlighted, plain) << "the dot is a problem marker, drawn only with problems shown";
}

TEST_F(RendererTest, OnlyTheDraggedHoseIsUploadedPerFrame)
{
    render();
    EXPECT_EQ(m_renderer.lastStats().hosesDrawn, 2);
    render();
    EXPECT_EQ(m_renderer.lastStats().hosesUploaded, 0);
    ASSERT_NE(m_document
                  .dragHosePoint("left-feed", 8,
                                 m_document.hose("left-feed")->point(8) + Vec3(0, 0.03, 0))
                  .status,
              Status::InvalidInput);
    render();
    EXPECT_EQ(m_renderer.lastStats().hosesUploaded, 1);
}

} // namespace
} // namespace chaintube::editor
