#include "viewport.h"

#include "chaintube/editor/commands.h"
#include "chaintube/editor/route_layout.h"

#include <Eigen/Geometry>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLFunctions>
#include <QPainter>
#include <QSurfaceFormat>
#include <QWheelEvent>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

namespace chaintube::editor {

namespace {
constexpr double kHandlePixels = 9.0;
constexpr double kMoveSnapMetres = 0.01;                       ///< Ctrl while moving a part
constexpr double kRotateSnapRadians = std::numbers::pi / 12.0; ///< Ctrl while rotating a part: 15°
} // namespace

Viewport::Viewport(Document& document, QWidget* parent)
    : QOpenGLWidget(parent), m_document(document)
{
    QSurfaceFormat format;
    format.setVersion(3, 3);
    format.setProfile(QSurfaceFormat::CoreProfile);
    format.setDepthBufferSize(24);
    // 4× multisampling by default; CHAINTUBE_STUDIO_SAMPLES overrides it (0 is much faster
    // with a software renderer such as Mesa's llvmpipe).
    bool haveSamples = false;
    const int samples = qEnvironmentVariableIntValue("CHAINTUBE_STUDIO_SAMPLES", &haveSamples);
    format.setSamples(haveSamples ? samples : 4);
    setFormat(format);
    setFocusPolicy(Qt::StrongFocus);
    setMouseTracking(true);
    setMinimumSize(320, 240);
    connect(&m_document, &Document::changed, this, &Viewport::onDocumentChanged);
    connect(&m_document, &Document::clearanceMarkersChanged, this, qOverload<>(&Viewport::update));
}

Viewport::~Viewport()
{
    if (m_initialised) {
        makeCurrent();
        m_renderer.releaseResources();
        doneCurrent();
    }
}

void Viewport::setMode(Mode mode)
{
    if (mode == m_mode) return;
    m_mode = mode;
    m_pendingRoute.clear();
    m_options.pendingRoute.clear();
    setCursor(mode == Mode::LayRoute || mode == Mode::PlaceSocket ? Qt::CrossCursor
              : mode == Mode::FixToPart                           ? Qt::PointingHandCursor
                                                                  : Qt::ArrowCursor);
    if (mode == Mode::LayRoute) {
        // The new hose's size is fixed when its layout starts: every clicked point goes out
        // from its surface by the same radius plus clearance.
        m_picker.update(m_document);
        m_newHoseDiameter = defaultHoseDiameter(m_picker.bounds());
        emit statusMessage(tr("New hose (%1 mm): click route points on the scene; Enter or "
                              "double-click finishes, Esc cancels")
                               .arg(m_newHoseDiameter * 1000.0, 0, 'g', 3));
    } else if (mode == Mode::Select)
        emit statusMessage(QString());
    emit modeChanged();
    update();
}

double Viewport::routeSurfaceDistance() const
{
    return routePointDistance(m_newHoseDiameter, m_routeClearance);
}

NearestSurfaceQuery Viewport::nearestSurfaceQuery() const
{
    return [this](const Vec3& at, double within) {
        NearestSurface near;
        near.found = m_picker.nearest(at, within, &near.point);
        return near;
    };
}

void Viewport::finishRoute()
{
    std::vector<Vec3> route = m_pendingRoute;
    setMode(Mode::Select);
    if (route.size() >= 2)
        emit routeFinished(route, m_newHoseDiameter);
    else
        emit statusMessage(tr("A hose needs at least two route points"));
}

void Viewport::cancelRoute()
{
    setMode(Mode::Select);
}

void Viewport::beginPlaceSocket()
{
    setMode(Mode::PlaceSocket);
    emit statusMessage(tr("Add socket: click on a part's surface (Esc cancels)"));
}

std::string Viewport::socketAt(const QPointF& position) const
{
    std::string nearest;
    double nearestPixels = 8.0;
    for (const formats::Socket& socket : m_document.project().sockets) {
        Vec3 centre, axis;
        if (!m_document.socketWorld(socket, &centre, &axis)) continue;
        const double pixels = (QPointF(toWidget(centre)) - position).manhattanLength();
        if (pixels <= nearestPixels) nearest = socket.id, nearestPixels = pixels;
    }
    return nearest;
}

void Viewport::placeSocketAt(const QPointF& position)
{
    ScenePickHit hit;
    if (!pickScene(position, &hit)) {
        emit statusMessage(tr("Click on a part's surface to place the socket (Esc cancels)"));
        return;
    }
    const formats::ImportedScene* scene = m_document.scene(hit.sceneId);
    const Frame part = m_document.nodeWorldFrame(hit.sceneId, hit.node);
    formats::Socket socket;
    socket.id = m_document.unusedSocketId();
    socket.scene = hit.sceneId;
    socket.node = scene->nodes[static_cast<size_t>(hit.node)].path;
    // In the part's frame, so that the socket moves with it; the axis points out of the surface.
    socket.position = part.applyInverse(hit.point);
    socket.axis = (part.rotation.conjugate() * hit.normal).normalized();
    socket.tag = "plug";
    try {
        m_document.undoStack()->push(makeAddSocket(m_document, socket));
    } catch (const std::exception& error) {
        emit statusMessage(tr("Cannot add the socket: %1").arg(error.what()));
        return;
    }
    Selection selection;
    selection.socketId = socket.id;
    m_document.setSelection(selection);
    setMode(Mode::Select);
    emit statusMessage(
        tr("Socket %1 on %2: set its tag, capture radius and angle in Properties")
            .arg(QString::fromStdString(socket.id),
                 QString::fromStdString(scene->nodes[static_cast<size_t>(hit.node)].name)));
}

void Viewport::beginClipToPart()
{
    const Selection& selection = m_document.selection();
    if (!m_document.hoseDefinition(selection.hoseId) || selection.rangeFirst < 0) {
        emit statusMessage(tr("Add clip: first click the hose point the clip holds"));
        return;
    }
    m_clipNext = true;
    setMode(Mode::FixToPart);
    emit statusMessage(
        tr("Clip point %1: click the part the clip is on (Esc cancels)").arg(selection.rangeFirst));
}

void Viewport::beginFixToPart()
{
    m_clipNext = false;
    const Selection& selection = m_document.selection();
    const formats::HoseDefinition* definition = m_document.hoseDefinition(selection.hoseId);
    if (!definition || selection.rangeFirst < 0) {
        emit statusMessage(tr("Fix to part: first click the hose point (or Shift+click the "
                              "points) to fix"));
        return;
    }
    setMode(Mode::FixToPart);
    const QString points =
        selection.rangeFirst == selection.rangeLast
            ? tr("point %1").arg(selection.rangeFirst)
            : tr("points %1–%2").arg(selection.rangeFirst).arg(selection.rangeLast);
    emit statusMessage(
        tr("Fix %1 of %2: click the part to fix it to (Esc cancels)")
            .arg(points, QString::fromStdString(definition->name.empty() ? definition->id
                                                                         : definition->name)));
}

void Viewport::fixSelectionToPartAt(const QPointF& position)
{
    ScenePickHit hit;
    if (!pickScene(position, &hit)) {
        emit statusMessage(tr("Click a part to fix the hose to (Esc cancels)"));
        return;
    }
    Selection selection = m_document.selection();
    try {
        m_document.closeMerge();
        if (m_clipNext)
            m_document.undoStack()->push(makeAddClip(m_document, selection.hoseId,
                                                     selection.rangeFirst, hit.sceneId, hit.node));
        else
            m_document.undoStack()->push(makeAttach(m_document, selection.hoseId,
                                                    selection.rangeFirst, selection.rangeLast,
                                                    hit.sceneId, hit.node));
        m_document.closeMerge();
    } catch (const std::exception& error) {
        emit statusMessage((m_clipNext ? tr("Cannot add the clip: %1") : tr("Cannot fix: %1"))
                               .arg(QString::fromStdString(error.what())));
        setMode(Mode::Select);
        return;
    }
    // The hose stays selected, the part too (its gizmo moves both).
    selection.sceneId = hit.sceneId;
    selection.node = hit.node;
    m_document.setSelection(selection);
    setMode(Mode::Select);
    emit statusMessage(m_document.undoStack()->text(m_document.undoStack()->index() - 1));
}

Vec3 Viewport::gizmoCentre() const
{
    const Selection& selection = m_document.selection();
    return m_document.partCentre(selection.sceneId, selection.node);
}

void Viewport::setWireframe(bool on)
{
    m_options.wireframe = on;
    update();
}

void Viewport::frameAll()
{
    m_picker.update(m_document);
    Box box = m_picker.bounds();
    for (const auto& definition : m_document.project().hoses)
        if (const Hose* hose = m_document.hose(definition.id))
            for (const Vec3& p : hose->points())
                box.extend(p);
    if (!box.empty()) m_camera.frame(box);
    update();
}

void Viewport::frameSelection()
{
    const Selection& selection = m_document.selection();
    Box box;
    if (const Hose* hose = m_document.hose(selection.hoseId)) {
        for (const Vec3& p : hose->points())
            box.extend(p);
    } else if (m_document.scene(selection.sceneId) && selection.node >= 0) {
        m_picker.update(m_document);
        box = m_picker.nodeBounds(selection.sceneId, selection.node);
        if (box.empty())
            box.extend(m_document.nodeWorldFrame(selection.sceneId, selection.node).translation);
    }
    if (box.empty()) {
        frameAll();
        return;
    }
    m_camera.frame(box);
    update();
}

QPoint Viewport::toWidget(const Vec3& world) const
{
    Eigen::Vector2d pixel;
    if (!m_camera.project(world, width(), height(), &pixel)) return QPoint(-1, -1);
    return QPoint(int(std::lround(pixel.x())), int(std::lround(pixel.y())));
}

Ray Viewport::rayAt(const QPointF& position) const
{
    return m_camera.rayThrough(position.x(), position.y(), width(), height());
}

bool Viewport::pickScene(const QPointF& position, ScenePickHit* hit)
{
    m_picker.update(m_document);
    return m_picker.pick(rayAt(position), hit);
}

QImage Viewport::renderToImage()
{
    return grabFramebuffer();
}

void Viewport::initializeGL()
{
    m_initialised = m_renderer.initialize();
    if (!m_initialised)
        emit statusMessage(tr("OpenGL initialisation failed: %1")
                               .arg(QString::fromStdString(m_renderer.errorString())));
    connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, [this] {
        makeCurrent();
        m_renderer.releaseResources();
        m_initialised = false;
        doneCurrent();
    });
}

void Viewport::paintGL()
{
    if (!m_initialised) return;
    if (!m_framedOnce) {
        m_framedOnce = true;
        frameAll();
    }
    const auto start = std::chrono::steady_clock::now();
    m_options.pendingRoute = m_pendingRoute;
    const qreal ratio = devicePixelRatioF();
    m_renderer.render(m_document, m_camera, int(width() * ratio), int(height() * ratio), m_options);
    if (m_options.showProblems) drawProblemLabels();
    if (m_finishEachFrame) context()->functions()->glFinish();
    m_lastFrameMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ++m_paintCount;
}

void Viewport::drawProblemLabels()
{
    // Beside the renderer's gap lines and kink rings: how much hose is missing, and the bend
    // radius a kink reached, so that the picture reads without the Problems panel.
    QPainter painter(this);
    painter.setRenderHint(QPainter::TextAntialiasing);
    QFont font = painter.font();
    font.setBold(true);
    painter.setFont(font);
    m_problemLabels.clear();
    const auto label = [&](const Vec3& at, const QString& text) {
        const QPoint p = toWidget(at);
        if (p.x() < 0) return;
        const QRect box = painter.fontMetrics().boundingRect(text).adjusted(-4, -2, 4, 2);
        QRect placed = box.translated(p + QPoint(12, -12) - box.bottomLeft());
        // Labels never cover one another (two hoses short at the same part): a label that
        // would is moved down below the one it meets, as often as needed.
        for (bool moved = true; moved;) {
            moved = false;
            for (const auto& [otherText, other] : m_problemLabels)
                if (placed.intersects(other)) {
                    placed.moveTop(other.bottom() + 3);
                    moved = true;
                }
        }
        m_problemLabels.push_back({text, placed});
        painter.fillRect(placed, QColor(40, 10, 10, 200));
        painter.setPen(QColor(255, 110, 100));
        painter.drawText(placed, Qt::AlignCenter, text);
    };
    for (const formats::HoseDefinition& definition : m_document.project().hoses) {
        const Hose* hose = m_document.hose(definition.id);
        const HoseMetrics* metrics = hose ? m_document.hoseMetrics(definition.id) : nullptr;
        if (!metrics) continue;
        for (const HoseMetrics::UnmetAttachment& unmet : metrics->unmetAttachments)
            for (const Hose::Attachment& attachment : hose->attachments())
                if (attachment.id == unmet.id)
                    label(0.5 * (hose->point(attachment.first) +
                                 attachment.frame.apply(attachment.localPoints.front())),
                          tr("%1 mm short").arg(unmet.gap * 1000.0, 0, 'f', 0));
        if (!metrics->bendBelowMinimum.empty())
            label(hose->point(metrics->smallestBendRadiusJoint >= 0
                                  ? metrics->smallestBendRadiusJoint
                                  : metrics->bendBelowMinimum.front()),
                  tr("kink: R %1 mm").arg(metrics->smallestBendRadius * 1000.0, 0, 'f', 0));
    }
}

void Viewport::onDocumentChanged(const ChangeEvent& event)
{
    if (event.kind == ChangeEvent::Kind::ProjectReplaced) {
        m_framedOnce = false;
        setMode(Mode::Select);
    }
    if (event.kind == ChangeEvent::Kind::FileStateChanged) return;
    update();
}

int Viewport::gizmoAxisAt(const QPointF& position, double* pixels) const
{
    const Selection& selection = m_document.selection();
    if (!m_document.scene(selection.sceneId) || selection.node < 0) return -1;
    const Vec3 origin = gizmoCentre();
    const QPointF a = toWidget(origin);
    int best = -1;
    double bestDistance = kHandlePixels;
    for (int axis = 0; axis < 3; ++axis) {
        const QPointF b = toWidget(origin + Renderer::gizmoLength(m_camera) * Vec3::Unit(axis));
        const QPointF ab = b - a;
        const double length2 = QPointF::dotProduct(ab, ab);
        if (length2 < 1.0) continue;
        // Only the outer 70 % of an arrow grabs, so that the node itself stays clickable.
        const double s = std::clamp(QPointF::dotProduct(position - a, ab) / length2, 0.3, 1.0);
        const QPointF closest = a + s * ab;
        const double distance = std::hypot(position.x() - closest.x(), position.y() - closest.y());
        if (distance < bestDistance) {
            bestDistance = distance;
            best = axis;
        }
    }
    if (pixels) *pixels = bestDistance;
    return best;
}

int Viewport::gizmoRingAt(const QPointF& position, double* pixels) const
{
    const Selection& selection = m_document.selection();
    if (!m_document.scene(selection.sceneId) || selection.node < 0) return -1;
    const Vec3 origin = gizmoCentre();
    int best = -1;
    double bestDistance = kHandlePixels;
    for (int axis = 0; axis < 3; ++axis) {
        const std::vector<Vec3> ring =
            Renderer::gizmoRing(origin, axis, Renderer::gizmoRingRadius(m_camera));
        QPointF previous = toWidget(ring.front());
        for (size_t i = 1; i < ring.size(); ++i) {
            const QPointF next = toWidget(ring[i]);
            const QPointF ab = next - previous;
            const double length2 = QPointF::dotProduct(ab, ab);
            const double s =
                length2 > 0
                    ? std::clamp(QPointF::dotProduct(position - previous, ab) / length2, 0.0, 1.0)
                    : 0.0;
            const QPointF closest = previous + s * ab;
            const double distance =
                std::hypot(position.x() - closest.x(), position.y() - closest.y());
            if (distance < bestDistance) {
                bestDistance = distance;
                best = axis;
            }
            previous = next;
        }
    }
    if (pixels) *pixels = bestDistance;
    return best;
}

double Viewport::gizmoScreenAngle(const QPointF& position) const
{
    const QPointF centre = toWidget(gizmoCentre());
    return std::atan2(position.y() - centre.y(), position.x() - centre.x());
}

int Viewport::axisPointAt(const Hose& hose, const QPointF& position) const
{
    int best = -1;
    double bestDistance = kHandlePixels;
    for (int i = 0; i < hose.pointCount(); ++i) {
        const QPointF p = toWidget(hose.point(i));
        const double distance = std::hypot(position.x() - p.x(), position.y() - p.y());
        if (distance < bestDistance) {
            bestDistance = distance;
            best = i;
        }
    }
    return best;
}

int Viewport::routePointAt(const QPointF& position) const
{
    const std::vector<Vec3> route = m_document.displayRoute(m_document.selection().hoseId);
    int best = -1;
    double bestDistance = kHandlePixels;
    for (size_t i = 0; i < route.size(); ++i) {
        const QPointF p = toWidget(route[i]);
        const double distance = std::hypot(position.x() - p.x(), position.y() - p.y());
        if (distance < bestDistance) {
            bestDistance = distance;
            best = int(i);
        }
    }
    return best;
}

Vec3 Viewport::onViewPlane(const QPointF& position, const Vec3& anchor) const
{
    const Ray ray = rayAt(position);
    const Vec3 normal = m_camera.forward();
    const double denominator = ray.direction.dot(normal);
    if (std::abs(denominator) < 1e-9) return anchor;
    const double t = (anchor - ray.origin).dot(normal) / denominator;
    return ray.origin + t * ray.direction;
}

void Viewport::mousePressEvent(QMouseEvent* event)
{
    const QPointF position = event->position();
    m_lastMouse = m_pressMouse = position;
    const bool orbitButton =
        event->button() == Qt::MiddleButton || event->button() == Qt::RightButton ||
        (event->button() == Qt::LeftButton && (event->modifiers() & Qt::AltModifier));
    if (orbitButton) {
        m_drag = (event->modifiers() & Qt::ShiftModifier) ? Drag::Pan : Drag::Orbit;
        return;
    }
    if (event->button() != Qt::LeftButton) return;

    if (m_mode == Mode::LayRoute) {
        ScenePickHit hit;
        if (pickScene(position, &hit)) {
            // Out of the part: the hose's surface keeps the clearance from the clicked surface.
            const double distance = routeSurfaceDistance();
            const SurfaceOffset placed =
                offsetFromSurface(hit.point, hit.surfaceNormal ? hit.normal : Vec3::Zero(),
                                  rayAt(position).direction, distance);
            // …and from every other surface near it (an inner corner, a groove, a neighbour).
            const ClearedRoutePoint cleared =
                keepClearOfSurfaces(placed, distance, nearestSurfaceQuery());
            m_pendingRoute.push_back(cleared.position);
            const QString part =
                QString::fromStdString(m_document.scene(hit.sceneId)->nodes[size_t(hit.node)].name);
            if (!cleared.clear)
                emit statusMessage(tr("Route point %1 on %2: only %3 mm from the nearest surface "
                                      "(%4 mm wanted; the gap is too narrow for the hose)")
                                       .arg(m_pendingRoute.size())
                                       .arg(part)
                                       .arg(cleared.clearance * 1000.0, 0, 'f', 1)
                                       .arg(distance * 1000.0, 0, 'f', 1));
            else
                emit statusMessage(
                    tr("Route point %1 on %2, %3 mm out%4")
                        .arg(m_pendingRoute.size())
                        .arg(part)
                        .arg(distance * 1000.0, 0, 'f', 1)
                        .arg(placed.alongSurfaceNormal
                                 ? QString()
                                 : tr(" towards the camera (no surface normal there)")));
        } else {
            emit statusMessage(tr("Click on a scene surface to place a route point"));
        }
        update();
        return;
    }

    if (m_mode == Mode::FixToPart) {
        fixSelectionToPartAt(position);
        update();
        return;
    }
    if (m_mode == Mode::PlaceSocket) {
        placeSocketAt(position);
        update();
        return;
    }

    Selection selection = m_document.selection();
    // 1. The gizmo of the selected part: an arrow moves it, a ring rotates it (the nearer
    // handle wins where they cross).
    double arrowPixels = 0.0, ringPixels = 0.0;
    const int axis = gizmoAxisAt(position, &arrowPixels);
    const int ring = gizmoRingAt(position, &ringPixels);
    if (ring >= 0 && (axis < 0 || ringPixels < arrowPixels)) {
        m_drag = Drag::GizmoRotate;
        m_gizmoAxis = ring;
        m_options.activeGizmoRing = ring;
        m_gizmoStartLocal = m_document.nodeLocalTransform(selection.sceneId, selection.node);
        m_gizmoStartOrigin = gizmoCentre();
        m_gizmoLastScreenAngle = gizmoScreenAngle(position);
        m_gizmoAngle = 0.0;
        m_document.closeMerge();
        update();
        return;
    }
    if (axis >= 0) {
        m_drag = Drag::Gizmo;
        m_gizmoAxis = axis;
        m_options.activeGizmoAxis = axis;
        m_gizmoStartLocal = m_document.nodeLocalTransform(selection.sceneId, selection.node);
        m_gizmoStartOrigin = gizmoCentre();
        const Ray ray = rayAt(position);
        const Vec3 a = Vec3::Unit(axis);
        const Vec3 w = ray.origin - m_gizmoStartOrigin;
        const double b = ray.direction.dot(a);
        m_gizmoStartParameter = (a.dot(w) - b * ray.direction.dot(w)) / std::max(1e-9, 1 - b * b);
        m_document.closeMerge();
        return;
    }
    // 2. A route point of the selected hose. A route handle lying on an axis point (the
    //    route's ends are the hose's ends; a route that is the hose's shape, as a committed
    //    drag leaves it, has a handle on every axis point) gives way to the hose point, so that
    //    the hose can be grabbed and its ends picked to be fixed; Ctrl+click takes the handle.
    int routePoint = routePointAt(position);
    if (routePoint >= 0 && !(event->modifiers() & Qt::ControlModifier)) {
        const Hose* hose = m_document.hose(selection.hoseId);
        const std::vector<Vec3> route = m_document.displayRoute(selection.hoseId);
        const int axisPoint = hose ? axisPointAt(*hose, position) : -1;
        if (axisPoint >= 0 && routePoint < static_cast<int>(route.size()) &&
            (toWidget(hose->point(axisPoint)) - toWidget(route[size_t(routePoint)]))
                    .manhattanLength() <= 2)
            routePoint = -1; // falls through to the hose pick below
    }
    if (routePoint >= 0 && m_document.hoseFollowsMovedPart(selection.hoseId)) {
        selection.routePoint = routePoint;
        m_document.setSelection(selection);
        emit statusMessage(tr("Route point %1: the hose is fixed to a moved part; its route is "
                              "kept at the file position (reset the part to edit it)")
                               .arg(routePoint));
        return;
    }
    if (routePoint >= 0) {
        selection.routePoint = routePoint;
        m_document.setSelection(selection);
        m_drag = Drag::RoutePoint;
        m_dragHose = selection.hoseId;
        m_dragIndex = routePoint;
        m_dragAnchor = m_document.hoseDefinition(selection.hoseId)->route[size_t(routePoint)];
        m_document.closeMerge();
        return;
    }
    // 3. A socket: the one whose centre is drawn nearest the cursor, within 8 pixels.
    if (const std::string socket = socketAt(position); !socket.empty()) {
        Selection picked;
        picked.socketId = socket;
        m_document.setSelection(picked);
        emit statusMessage(tr("Socket %1: its tag, capture radius and angle are in Properties")
                               .arg(QString::fromStdString(socket)));
        update();
        return;
    }
    // 4. A hose, 5. a scene part, 6. nothing. Whichever is nearer along the ray wins.
    selection.socketId.clear();
    const Ray ray = rayAt(position);
    const double pixelMetres =
        2.0 * m_camera.distance * std::tan(m_camera.fieldOfViewY / 2) / std::max(height(), 1);
    HosePickHit hoseHit;
    ScenePickHit sceneHit;
    const bool onHose = pickHose(m_document, ray, 3.0 * pixelMetres, &hoseHit);
    const bool onScene = pickScene(position, &sceneHit);
    if (onHose && (!onScene || hoseHit.distance <= sceneHit.distance + 0.02)) {
        // The axis point drawn nearest the cursor wins over the one nearest along the ray
        // (a hose seen end-on passes several points under the cursor): a click on a drawn
        // point, an end in particular, picks that point.
        if (const Hose* hose = m_document.hose(hoseHit.hoseId)) {
            const int nearest = axisPointAt(*hose, position);
            if (nearest >= 0) hoseHit.point = nearest, hoseHit.position = hose->point(nearest);
        }
        const bool extend = (event->modifiers() & Qt::ShiftModifier) &&
                            selection.hoseId == hoseHit.hoseId && selection.rangeFirst >= 0;
        if (selection.hoseId != hoseHit.hoseId) selection.routePoint = -1;
        selection.hoseId = hoseHit.hoseId;
        selection.routePoint = -1;
        if (extend) {
            // Shift+click: the range between the point clicked before and this one.
            const int anchor = m_rangeAnchor >= 0 ? m_rangeAnchor : selection.rangeFirst;
            selection.rangeFirst = std::min(anchor, hoseHit.point);
            selection.rangeLast = std::max(anchor, hoseHit.point);
        } else {
            selection.rangeFirst = selection.rangeLast = hoseHit.point;
            m_rangeAnchor = hoseHit.point;
        }
        m_document.setSelection(selection);
        const Hose* hose = m_document.hose(hoseHit.hoseId);
        if (!extend && hose && !hose->isFixed(hoseHit.point)) {
            m_drag = Drag::HosePoint;
            m_dragHose = hoseHit.hoseId;
            m_dragIndex = hoseHit.point;
            m_dragAnchor = hoseHit.position;
            // Keep the offset between the picked spot and the axis point while dragging.
            m_dragGrabOffset = hoseHit.position - onViewPlane(position, hoseHit.position);
        }
        emit statusMessage(
            tr("Hose %1, axis point %2%3")
                .arg(QString::fromStdString(hoseHit.hoseId))
                .arg(hoseHit.point)
                .arg(hose && hose->isFixed(hoseHit.point) ? tr(" (fixed)") : QString()));
    } else if (onScene) {
        selection.sceneId = sceneHit.sceneId;
        selection.node = sceneHit.node;
        m_document.setSelection(selection);
        emit statusMessage(tr("Part %1").arg(QString::fromStdString(
            m_document.scene(sceneHit.sceneId)->nodes[size_t(sceneHit.node)].path)));
    } else {
        m_document.setSelection(Selection());
    }
}

void Viewport::mouseMoveEvent(QMouseEvent* event)
{
    const QPointF position = event->position();
    const QPointF delta = position - m_lastMouse;
    m_lastMouse = position;
    switch (m_drag) {
    case Drag::Orbit:
        m_camera.orbit(delta.x(), delta.y());
        update();
        break;
    case Drag::Pan:
        m_camera.pan(delta.x(), delta.y(), height());
        update();
        break;
    case Drag::HosePoint: {
        const Vec3 target = onViewPlane(position, m_dragAnchor) + m_dragGrabOffset;
        const UpdateResult result = m_document.dragHosePoint(m_dragHose, m_dragIndex, target);
        // (Pending: the budget of a mouse move ran out, the next one goes on.)
        if (result.status == Status::Clamped && !result.pending)
            emit statusMessage(tr("Out of reach: the hose is as long as it can stretch"));
        break;
    }
    case Drag::RoutePoint: {
        const formats::HoseDefinition* definition = m_document.hoseDefinition(m_dragHose);
        if (!definition) break;
        std::vector<Vec3> route = definition->route;
        route[size_t(m_dragIndex)] = onViewPlane(position, m_dragAnchor);
        m_document.undoStack()->push(
            makeSetRoute(m_document, m_dragHose, route,
                         tr("Move route point %1 of %2")
                             .arg(m_dragIndex)
                             .arg(QString::fromStdString(
                                 definition->name.empty() ? definition->id : definition->name)),
                         MergeId::HoseRoute));
        break;
    }
    case Drag::Gizmo: {
        const Selection& selection = m_document.selection();
        const Ray ray = rayAt(position);
        const Vec3 a = Vec3::Unit(m_gizmoAxis);
        const Vec3 w = ray.origin - m_gizmoStartOrigin;
        const double b = ray.direction.dot(a);
        const double parameter = (a.dot(w) - b * ray.direction.dot(w)) / std::max(1e-9, 1 - b * b);
        Vec3 shift = (parameter - m_gizmoStartParameter) * a;
        const formats::Mat4 world =
            m_document.nodeWorldTransform(selection.sceneId, selection.node);
        const formats::Mat4 current =
            m_document.nodeLocalTransform(selection.sceneId, selection.node);
        const formats::Mat4 parentWorld = world * current.inverse();
        // Ctrl snaps the part's offset along the axis from where its scene file puts it to
        // whole centimetres (not steps from where the drag began): a part moved by any amount
        // snaps back onto its place.
        if (event->modifiers() & Qt::ControlModifier) {
            const formats::Mat4& fileLocal =
                m_document.scene(selection.sceneId)->nodes[size_t(selection.node)].localTransform;
            const Vec3 fromFile = (parentWorld * m_gizmoStartLocal).block<3, 1>(0, 3) -
                                  (parentWorld * fileLocal).block<3, 1>(0, 3);
            const double before = fromFile.dot(a);
            const double snapped =
                std::round((before + shift.dot(a)) / kMoveSnapMetres) * kMoveSnapMetres;
            shift = a * (snapped - before);
        }
        // newLocal = parentWorld⁻¹ · T(shift) · parentWorld · startLocal.
        formats::Mat4 translation = formats::Mat4::Identity();
        translation.block<3, 1>(0, 3) = shift;
        const formats::Mat4 local =
            parentWorld.inverse() * translation * parentWorld * m_gizmoStartLocal;
        m_document.undoStack()->push(
            makeSetNodeTransform(m_document, {selection.sceneId, selection.node}, local));
        break;
    }
    case Drag::GizmoRotate: {
        // The angle follows the mouse around the gizmo centre on screen, unwrapped so that
        // several turns add up; its sign depends on whether the axis faces the viewer.
        const Selection& selection = m_document.selection();
        const double screenAngle = gizmoScreenAngle(position);
        double step = screenAngle - m_gizmoLastScreenAngle;
        step -= 2 * std::numbers::pi * std::round(step / (2 * std::numbers::pi));
        m_gizmoLastScreenAngle = screenAngle;
        const Vec3 a = Vec3::Unit(m_gizmoAxis);
        const bool facesViewer = a.dot(m_camera.eye() - m_gizmoStartOrigin) > 0;
        m_gizmoAngle += facesViewer ? -step : step;
        double angle = m_gizmoAngle;
        // Ctrl snaps to 15° steps.
        if (event->modifiers() & Qt::ControlModifier)
            angle = std::round(angle / kRotateSnapRadians) * kRotateSnapRadians;
        // newLocal = parentWorld⁻¹ · T(o) · R(angle about a) · T(−o) · parentWorld · startLocal.
        const formats::Mat4 world =
            m_document.nodeWorldTransform(selection.sceneId, selection.node);
        const formats::Mat4 current =
            m_document.nodeLocalTransform(selection.sceneId, selection.node);
        const formats::Mat4 parentWorld = world * current.inverse();
        formats::Mat4 rotation = formats::Mat4::Identity();
        rotation.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, a).toRotationMatrix();
        rotation.topRightCorner<3, 1>() =
            m_gizmoStartOrigin - rotation.topLeftCorner<3, 3>() * m_gizmoStartOrigin;
        const formats::Mat4 local =
            parentWorld.inverse() * rotation * parentWorld * m_gizmoStartLocal;
        m_document.undoStack()->push(makeSetNodeTransform(
            m_document, {selection.sceneId, selection.node}, local,
            tr("Rotate %1")
                .arg(QString::fromStdString(
                    m_document.scene(selection.sceneId)->nodes[size_t(selection.node)].name))));
        emit statusMessage(tr("Rotate about %1: %2°%3")
                               .arg(QChar("XYZ"[m_gizmoAxis]))
                               .arg(angle * 180.0 / std::numbers::pi, 0, 'f', 1)
                               .arg(event->modifiers() & Qt::ControlModifier
                                        ? QString()
                                        : tr(" (hold Ctrl to snap to 15°)")));
        break;
    }
    case Drag::None:
        if (m_mode == Mode::Select) {
            double arrowPixels = 0.0, ringPixels = 0.0;
            int axis = gizmoAxisAt(position, &arrowPixels);
            int ring = gizmoRingAt(position, &ringPixels);
            if (ring >= 0 && axis >= 0) (ringPixels < arrowPixels ? axis : ring) = -1;
            if (axis != m_options.activeGizmoAxis || ring != m_options.activeGizmoRing) {
                m_options.activeGizmoAxis = axis;
                m_options.activeGizmoRing = ring;
                update();
            }
        }
        break;
    }
}

void Viewport::mouseReleaseEvent(QMouseEvent*)
{
    const Drag drag = m_drag;
    m_drag = Drag::None;
    m_options.activeGizmoAxis = -1;
    m_options.activeGizmoRing = -1;
    if (drag == Drag::HosePoint) {
        // The release converges fully, without the live drag's budget.
        static_cast<void>(m_document.finishHoseDrag(m_dragHose));
        const Hose* hose = m_document.hose(m_dragHose);
        const bool moved = hose && (hose->point(m_dragIndex) - m_dragAnchor).norm() > 1e-12;
        if (moved) {
            std::string why;
            if (!m_document.commitHoseDrag(m_dragHose, m_dragIndex, &why))
                emit statusMessage(QString::fromStdString(why));
        }
    }
    m_document.closeMerge();
    update();
}

void Viewport::mouseDoubleClickEvent(QMouseEvent* event)
{
    if (m_mode == Mode::LayRoute && event->button() == Qt::LeftButton) {
        finishRoute();
        return;
    }
    if (event->button() == Qt::LeftButton) frameSelection();
}

void Viewport::wheelEvent(QWheelEvent* event)
{
    m_camera.zoom(event->angleDelta().y() / 120.0);
    update();
}

} // namespace chaintube::editor
