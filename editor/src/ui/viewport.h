// ChainTube editor — the 3D viewport: a QOpenGLWidget over Renderer, with orbit/pan/zoom,
// picking, laying out a route by clicks, grab-dragging hose points, dragging route points and
// the part gizmo. It only reads the Document and changes it through commands.
#pragma once

#include "chaintube/editor/camera.h"
#include "chaintube/editor/document.h"
#include "chaintube/editor/picking.h"
#include "chaintube/editor/renderer.h"
#include "chaintube/editor/route_layout.h"

#include <QElapsedTimer>
#include <QOpenGLWidget>
#include <algorithm>
#include <memory>
#include <vector>

namespace chaintube::editor {

class Viewport : public QOpenGLWidget
{
    Q_OBJECT
public:
    enum class Mode {
        Select,      ///< click selects; drag moves hose points, route points, the gizmo
        LayRoute,    ///< clicks on scene surfaces add route points of a new hose
        FixToPart,   ///< the next click on a part fixes the selected hose points to it
        PlaceSocket, ///< the next click on a part's surface adds a socket there (makeAddSocket)
    };

    explicit Viewport(Document& document, QWidget* parent = nullptr);
    ~Viewport() override;

    Camera& camera() { return m_camera; }
    Mode mode() const { return m_mode; }
    void setMode(Mode mode);
    /// Outer diameter (metres) of the hose being laid out: defaultHoseDiameter() of the scene's
    /// world bounds when LayRoute mode began.
    double newHoseDiameter() const { return m_newHoseDiameter; }
    /// Clearance (metres ≥ 0) a clicked route point keeps: it goes out from the clicked surface
    /// by the new hose's outer radius plus this (offsetFromSurface). The main window keeps it
    /// equal to the Problems panel's clearance threshold.
    void setRouteClearance(double metres) { m_routeClearance = std::max(0.0, metres); }
    double routeClearance() const { return m_routeClearance; }
    /// How far a clicked route point goes out from its surface: radius plus clearance
    /// (routePointDistance).
    double routeSurfaceDistance() const;
    /// Route points clicked so far in LayRoute mode (world metres), already out of the surface.
    const std::vector<Vec3>& pendingRoute() const { return m_pendingRoute; }
    /// The nearest scene surface to a position (world metres) within a distance: what route
    /// points are cleared against.
    NearestSurfaceQuery nearestSurfaceQuery() const;
    /// Ends LayRoute mode; with ≥ 2 points emits routeFinished(points, newHoseDiameter()).
    void finishRoute();
    void cancelRoute();
    /// Fixing in one gesture: with hose points selected, the next click on a part fixes them
    /// to it (one undo step; the hose stays selected) and the mode ends. Without selected
    /// hose points it only says what to select first. Esc (cancelRoute) leaves the mode.
    void beginFixToPart();
    /// As beginFixToPart, for a clip at the selected hose point (makeAddClip).
    void beginClipToPart();
    /// "Add Socket": the next click on a part's surface adds a socket there (its axis the
    /// surface normal, in the part's frame), selects it and ends the mode; Esc cancels.
    void beginPlaceSocket();

    bool wireframe() const { return m_options.wireframe; }
    void setWireframe(bool on);
    /// Frames the selection (hose, node) or, with nothing selected, everything.
    void frameSelection();
    void frameAll();

    /// Widget coordinates (logical pixels) of a world point.
    QPoint toWidget(const Vec3& world) const;
    /// The id of the socket whose centre is drawn nearest `position`, within 8 pixels ("" for
    /// none); a click there selects it.
    std::string socketAt(const QPointF& position) const;
    /// Ray through a widget position (logical pixels).
    Ray rayAt(const QPointF& position) const;
    /// Picks scene triangles under a widget position.
    bool pickScene(const QPointF& position, ScenePickHit* hit);

    /// Milliseconds the last paintGL took (CPU side, including surface updates; with
    /// setFinishEachFrame(true) also until the GPU finished).
    double lastFrameMilliseconds() const { return m_lastFrameMilliseconds; }
    void setFinishEachFrame(bool finish) { m_finishEachFrame = finish; }
    /// The problem labels of the last frame ("… mm short", "kink: R … mm"): text and where
    /// (widget pixels). No two overlap.
    const std::vector<std::pair<QString, QRect>>& problemLabels() const { return m_problemLabels; }
    /// Number of paintGL calls so far.
    long long paintCount() const { return m_paintCount; }
    const RenderStats& lastRenderStats() const { return m_renderer.lastStats(); }
    /// Renders into an image of the viewport's size (for screenshots).
    QImage renderToImage();

signals:
    /// A route laid out by clicks (≥ 2 points) for a new hose of outer diameter
    /// `outerDiameter` metres.
    void routeFinished(const std::vector<chaintube::Vec3>& route, double outerDiameter);
    void statusMessage(const QString& message);
    void modeChanged();

protected:
    void initializeGL() override;
    void paintGL() override;
    void mousePressEvent(QMouseEvent* event) override;
    void mouseMoveEvent(QMouseEvent* event) override;
    void mouseReleaseEvent(QMouseEvent* event) override;
    void mouseDoubleClickEvent(QMouseEvent* event) override;
    void wheelEvent(QWheelEvent* event) override;

private:
    enum class Drag { None, Orbit, Pan, HosePoint, RoutePoint, Gizmo, GizmoRotate };
    void onDocumentChanged(const ChangeEvent& event);
    /// Text beside the problem markers: "37 mm short", "kink: R 31 mm".
    void drawProblemLabels();
    int gizmoAxisAt(const QPointF& position, double* pixels = nullptr) const;
    /// The rotate ring (0 x, 1 y, 2 z) within a few pixels of `position`, or −1.
    int gizmoRingAt(const QPointF& position, double* pixels = nullptr) const;
    /// Screen angle (radians, widget coordinates) of `position` around the gizmo centre.
    double gizmoScreenAngle(const QPointF& position) const;
    int routePointAt(const QPointF& position) const;
    /// The axis point of `hose` drawn nearest `position` within a handle's reach, or −1.
    int axisPointAt(const Hose& hose, const QPointF& position) const;
    /// Where the mouse ray meets the plane through `anchor` facing the camera.
    Vec3 onViewPlane(const QPointF& position, const Vec3& anchor) const;

    /// The gizmo's centre: the selected part's bounding-box centre (Document::partCentre).
    Vec3 gizmoCentre() const;
    /// In FixToPart mode: fixes the selected hose points to the part under `position`.
    void fixSelectionToPartAt(const QPointF& position);
    void placeSocketAt(const QPointF& position);

    Document& m_document;
    Renderer m_renderer;
    Camera m_camera;
    ScenePicker m_picker;
    RenderOptions m_options;
    Mode m_mode = Mode::Select;
    bool m_clipNext = false; ///< FixToPart adds a clip at the selected point instead
    std::vector<Vec3> m_pendingRoute;
    double m_newHoseDiameter = 0.02;
    double m_routeClearance = 0.005;
    bool m_initialised = false;
    bool m_framedOnce = false;

    Drag m_drag = Drag::None;
    QPointF m_lastMouse;
    QPointF m_pressMouse;
    std::string m_dragHose;
    int m_dragIndex = -1;
    int m_rangeAnchor = -1; ///< the axis point a Shift+click selects the range from
    Vec3 m_dragAnchor = Vec3::Zero();
    Vec3 m_dragGrabOffset = Vec3::Zero();
    int m_gizmoAxis = -1;
    formats::Mat4 m_gizmoStartLocal;
    Vec3 m_gizmoStartOrigin = Vec3::Zero();
    double m_gizmoStartParameter = 0.0;
    double m_gizmoLastScreenAngle = 0.0; ///< rotate drag: unwrapped through every move
    double m_gizmoAngle = 0.0;           ///< rotate drag: total angle about the axis, radians

    double m_lastFrameMilliseconds = 0.0;
    bool m_finishEachFrame = false;
    std::vector<std::pair<QString, QRect>> m_problemLabels;
    long long m_paintCount = 0;
};

} // namespace chaintube::editor
