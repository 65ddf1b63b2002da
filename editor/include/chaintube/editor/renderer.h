// ChainTube editor — OpenGL 3.3 core renderer of a Document: scene meshes, hose surfaces,
// route points, problem highlights (overstretched or kinked rings, unreached attachments), the
// part gizmo.
//
// The renderer draws into whatever framebuffer is bound when render() is called: the
// viewport's QOpenGLWidget framebuffer, or a QOpenGLFramebufferObject in tests (offscreen, no
// window). It keeps GPU copies of scene meshes and hose surfaces and updates a hose's vertex
// buffers only when the hose's revision changed, so a frame while dragging one hose uploads
// one hose.
#pragma once

#include "chaintube/editor/camera.h"
#include "chaintube/editor/document.h"

#include <QColor>
#include <memory>
#include <string>
#include <vector>

namespace chaintube::editor {

/// What to draw besides the document.
struct RenderOptions
{
    bool wireframe = false;         ///< polygon mode lines for scene meshes and hoses
    bool showProblems = true;       ///< tint rings of problem regions red
    bool showGizmo = true;          ///< axis arrows at the selected node
    int activeGizmoAxis = -1;       ///< 0 x, 1 y, 2 z drawn highlighted (being dragged/hovered)
    int activeGizmoRing = -1;       ///< rotate ring about x/y/z (0/1/2) drawn highlighted
    std::vector<Vec3> pendingRoute; ///< route points of a hose being laid out (world)
    QColor background = QColor(58, 62, 70);
};

/// What the last render() did.
struct RenderStats
{
    int hosesUploaded = 0; ///< hoses whose vertex buffers were updated
    int hosesDrawn = 0;
    long long trianglesDrawn = 0;
    double hoseUpdateMilliseconds = 0.0; ///< CPU time of surface updates + uploads
};

class Renderer
{
public:
    Renderer();
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    /// Compiles shaders. An OpenGL 3.3 core (or compatible) context must be current.
    /// Returns false and sets errorString() on failure.
    bool initialize();
    const std::string& errorString() const { return m_error; }

    /// Draws the document seen by `camera` into the bound framebuffer of width × height
    /// device pixels. The context given to initialize() must be current.
    void render(const Document& document, const Camera& camera, int width, int height,
                const RenderOptions& options = {});
    const RenderStats& lastStats() const { return m_stats; }

    /// Frees GPU objects; the context must be current. Called by the destructor if the
    /// context is still current then.
    void releaseResources();

    /// Length (metres) of the gizmo arrows for a camera: a fixed fraction of the view.
    static double gizmoLength(const Camera& camera);
    /// The colour a part (a scene node with meshes) is drawn in, sRGB: the k-th node with
    /// meshes of its scene (file order) gets the k-th of eight muted colours (k mod 8), so
    /// neighbouring parts of a small scene differ (the test rig's floor, brackets and valve
    /// all do). None is azure (the selection tint) or red (problems).
    static QColor partColour(const formats::ImportedScene& scene, int node);
    /// Radius (metres) of the rotate gizmo's rings: inside the arrows, so that the arrow tips
    /// stay apart from the rings.
    static double gizmoRingRadius(const Camera& camera);
    /// The closed polyline (25 points) of the marker drawn around a kinked joint: a circle of
    /// `radius` metres about `centre` in the plane facing `normal` (world).
    static std::vector<Vec3> kinkRing(const Vec3& centre, const Vec3& normal, double radius);
    /// The closed polyline of the rotate ring about world axis `axis` (0 x, 1 y, 2 z) centred
    /// at `centre` (world metres): `segments` + 1 points, the last equal to the first. The
    /// viewport picks against the same points.
    static std::vector<Vec3> gizmoRing(const Vec3& centre, int axis, double radius,
                                       int segments = 64);

private:
    struct Private;
    std::unique_ptr<Private> d;
    std::string m_error;
    RenderStats m_stats;
};

} // namespace chaintube::editor
