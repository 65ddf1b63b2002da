#include "chaintube/editor/renderer.h"

#include "chaintube/surface.h"

#include <QOpenGLContext>
#include <QOpenGLFunctions_3_3_Core>
#include <QOpenGLShaderProgram>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

namespace chaintube::editor {

namespace {

const char* kSurfaceVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in float flag;
uniform mat4 model;
uniform mat4 viewProjection;
uniform mat3 normalMatrix;
out vec3 worldNormal;
out vec3 worldPosition;
out float problem;
void main()
{
    vec4 world = model * vec4(position, 1.0);
    worldPosition = world.xyz;
    worldNormal = normalMatrix * normal;
    problem = flag;
    gl_Position = viewProjection * world;
}
)";

const char* kSurfaceFragmentShader = R"(#version 330 core
in vec3 worldNormal;
in vec3 worldPosition;
in float problem;
uniform vec4 colour;
uniform vec3 eye;
uniform float highlight;   // 0 … 1: selection tint (azure: never a problem colour)
uniform float roughness;
out vec4 fragmentColour;
void main()
{
    vec3 n = normalize(worldNormal);
    vec3 toEye = normalize(eye - worldPosition);
    if (dot(n, toEye) < 0.0)
        n = -n;
    vec3 key = normalize(vec3(0.35, 1.0, 0.45));
    vec3 base = colour.rgb;
    base = mix(base, vec3(0.15, 0.7, 1.0), highlight * 0.75);
    float red = clamp(problem, 0.0, 1.0);
    base = mix(base, vec3(0.95, 0.08, 0.05), red);
    float headlight = max(dot(n, toEye), 0.0);
    float keyLight = max(dot(n, key), 0.0);
    vec3 halfway = normalize(key + toEye);
    float shininess = mix(64.0, 4.0, roughness);
    float specular = pow(max(dot(n, halfway), 0.0), shininess) * (1.0 - roughness) * 0.5;
    vec3 lit = base * (0.22 + 0.5 * headlight + 0.35 * keyLight) + vec3(specular);
    fragmentColour = vec4(pow(lit, vec3(1.0 / 1.6)), 1.0);
}
)";

const char* kLineVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 viewProjection;
uniform float pointSize;
void main()
{
    gl_Position = viewProjection * vec4(position, 1.0);
    gl_PointSize = pointSize;
}
)";

const char* kLineFragmentShader = R"(#version 330 core
uniform vec4 colour;
uniform bool roundPoints;
out vec4 fragmentColour;
void main()
{
    if (roundPoints && length(gl_PointCoord - vec2(0.5)) > 0.5)
        discard;
    fragmentColour = colour;
}
)";

Eigen::Matrix4f toFloat(const Eigen::Matrix4d& m)
{
    return m.cast<float>();
}

QColor linearToDisplay(const formats::Rgba& colour)
{
    return QColor::fromRgbF(float(colour.r), float(colour.g), float(colour.b), float(colour.a));
}

} // namespace

struct Renderer::Private : QOpenGLFunctions_3_3_Core
{
    struct GpuMesh
    {
        GLuint vao = 0, positions = 0, normals = 0, indices = 0;
        GLsizei indexCount = 0;
        bool used = false;
    };
    struct GpuHose
    {
        std::uint64_t buildSerial = 0;
        std::uint64_t uploadedRevision = 0;
        std::uint64_t flagsRevision = ~0ull;
        std::unique_ptr<HoseSurface> surface;
        GLuint vao = 0, positions = 0, normals = 0, flags = 0, indices = 0;
        GLsizei indexCount = 0;
        bool used = false;
    };

    QOpenGLContext* context = nullptr;
    QOpenGLShaderProgram surfaceProgram;
    QOpenGLShaderProgram lineProgram;
    GLuint lineVao = 0, lineBuffer = 0;
    std::map<const formats::SceneMesh*, GpuMesh> meshes;
    std::map<std::string, GpuHose> hoses;

    void deleteMesh(GpuMesh& mesh)
    {
        glDeleteVertexArrays(1, &mesh.vao);
        GLuint buffers[] = {mesh.positions, mesh.normals, mesh.indices};
        glDeleteBuffers(3, buffers);
    }
    void deleteHose(GpuHose& hose)
    {
        glDeleteVertexArrays(1, &hose.vao);
        GLuint buffers[] = {hose.positions, hose.normals, hose.flags, hose.indices};
        glDeleteBuffers(4, buffers);
    }

    GpuMesh& meshFor(const formats::SceneMesh& mesh)
    {
        GpuMesh& gpu = meshes[&mesh];
        gpu.used = true;
        if (gpu.vao) return gpu;
        glGenVertexArrays(1, &gpu.vao);
        glBindVertexArray(gpu.vao);
        glGenBuffers(1, &gpu.positions);
        glBindBuffer(GL_ARRAY_BUFFER, gpu.positions);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.positions.size() * sizeof(float)),
                     mesh.positions.data(), GL_STATIC_DRAW);
        glEnableVertexAttribArray(0);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
        glGenBuffers(1, &gpu.normals);
        glBindBuffer(GL_ARRAY_BUFFER, gpu.normals);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.normals.size() * sizeof(float)),
                     mesh.normals.data(), GL_STATIC_DRAW);
        glEnableVertexAttribArray(1);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
        glDisableVertexAttribArray(2);
        glGenBuffers(1, &gpu.indices);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.indices);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                     GLsizeiptr(mesh.indices.size() * sizeof(std::uint32_t)), mesh.indices.data(),
                     GL_STATIC_DRAW);
        gpu.indexCount = GLsizei(mesh.indices.size());
        glBindVertexArray(0);
        return gpu;
    }

    /// Per-vertex problem flags (1 = ring in a problem region) of a hose.
    static std::vector<float> problemFlags(const Hose& hose, const HoseMetrics& metrics,
                                           const SurfaceTopology& topology)
    {
        std::vector<char> ringFlag(static_cast<size_t>(hose.pointCount()), 0);
        for (int s = 0; s < hose.segmentCount(); ++s) {
            const double length = (hose.point(s + 1) - hose.point(s)).norm();
            if (length > hose.maxLength(s) * (1.0 + 1e-6) ||
                length < hose.minLength(s) * (1.0 - 1e-6))
                ringFlag[static_cast<size_t>(s)] = ringFlag[static_cast<size_t>(s) + 1] = 1;
        }
        for (int joint : metrics.bendBelowMinimum)
            ringFlag[static_cast<size_t>(joint)] = 1;
        for (int segment : metrics.selfIntersectingSegments)
            ringFlag[static_cast<size_t>(segment)] = ringFlag[static_cast<size_t>(segment) + 1] = 1;
        std::vector<float> flags(static_cast<size_t>(topology.vertexCount), 0.0f);
        for (size_t v = 0; v < flags.size(); ++v) {
            const std::uint32_t ring = topology.vertexRing[v];
            if (ring < ringFlag.size() && ringFlag[ring]) flags[v] = 1.0f;
        }
        return flags;
    }

    GpuHose& hoseFor(const Document& document, const std::string& id, const Hose& hose,
                     bool showProblems, RenderStats& stats)
    {
        GpuHose& gpu = hoses[id];
        gpu.used = true;
        const std::uint64_t serial = document.hoseBuildSerial(id);
        if (!gpu.surface || gpu.buildSerial != serial) {
            if (gpu.vao) deleteHose(gpu);
            gpu = GpuHose();
            gpu.used = true;
            gpu.buildSerial = serial;
            gpu.surface = std::make_unique<HoseSurface>(hose);
            const SurfaceTopology& topology = gpu.surface->topology();
            glGenVertexArrays(1, &gpu.vao);
            glBindVertexArray(gpu.vao);
            const GLsizeiptr floats3 = GLsizeiptr(3 * topology.vertexCount * sizeof(float));
            glGenBuffers(1, &gpu.positions);
            glBindBuffer(GL_ARRAY_BUFFER, gpu.positions);
            glBufferData(GL_ARRAY_BUFFER, floats3, nullptr, GL_DYNAMIC_DRAW);
            glEnableVertexAttribArray(0);
            glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
            glGenBuffers(1, &gpu.normals);
            glBindBuffer(GL_ARRAY_BUFFER, gpu.normals);
            glBufferData(GL_ARRAY_BUFFER, floats3, nullptr, GL_DYNAMIC_DRAW);
            glEnableVertexAttribArray(1);
            glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
            glGenBuffers(1, &gpu.flags);
            glBindBuffer(GL_ARRAY_BUFFER, gpu.flags);
            glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(topology.vertexCount * sizeof(float)), nullptr,
                         GL_DYNAMIC_DRAW);
            glEnableVertexAttribArray(2);
            glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, 0, nullptr);
            glGenBuffers(1, &gpu.indices);
            glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.indices);
            glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                         GLsizeiptr(topology.indices.size() * sizeof(std::uint32_t)),
                         topology.indices.data(), GL_STATIC_DRAW);
            gpu.indexCount = GLsizei(topology.indices.size());
            glBindVertexArray(0);
        }
        if (gpu.uploadedRevision != hose.revision()) {
            gpu.surface->update(hose);
            const std::span<const float> positions = gpu.surface->positions();
            const std::span<const float> normals = gpu.surface->normals();
            glBindBuffer(GL_ARRAY_BUFFER, gpu.positions);
            glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(positions.size() * sizeof(float)),
                            positions.data());
            glBindBuffer(GL_ARRAY_BUFFER, gpu.normals);
            glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(normals.size() * sizeof(float)),
                            normals.data());
            gpu.uploadedRevision = hose.revision();
            ++stats.hosesUploaded;
        }
        const std::uint64_t flagsRevision = showProblems ? hose.revision() : 0;
        if (gpu.flagsRevision != flagsRevision) {
            const SurfaceTopology& topology = gpu.surface->topology();
            std::vector<float> flags(static_cast<size_t>(topology.vertexCount), 0.0f);
            if (showProblems)
                if (const HoseMetrics* metrics = document.hoseMetrics(id))
                    flags = problemFlags(hose, *metrics, topology);
            glBindBuffer(GL_ARRAY_BUFFER, gpu.flags);
            glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(flags.size() * sizeof(float)),
                            flags.data());
            gpu.flagsRevision = flagsRevision;
        }
        return gpu;
    }

    void drawLines(const std::vector<Vec3>& points, GLenum mode, const QColor& colour,
                   float pointSize, const Eigen::Matrix4f& viewProjection)
    {
        if (points.empty()) return;
        std::vector<float> data;
        data.reserve(points.size() * 3);
        for (const Vec3& p : points)
            for (int i = 0; i < 3; ++i)
                data.push_back(float(p[i]));
        lineProgram.bind();
        glUniformMatrix4fv(lineProgram.uniformLocation("viewProjection"), 1, GL_FALSE,
                           viewProjection.data());
        lineProgram.setUniformValue("colour", colour);
        lineProgram.setUniformValue("pointSize", pointSize);
        lineProgram.setUniformValue("roundPoints", mode == GL_POINTS);
        glBindVertexArray(lineVao);
        glBindBuffer(GL_ARRAY_BUFFER, lineBuffer);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(),
                     GL_STREAM_DRAW);
        glDrawArrays(mode, 0, GLsizei(points.size()));
        glBindVertexArray(0);
    }
};

Renderer::Renderer() : d(std::make_unique<Private>()) {}

Renderer::~Renderer()
{
    if (d->context && QOpenGLContext::currentContext() == d->context) releaseResources();
}

bool Renderer::initialize()
{
    d->context = QOpenGLContext::currentContext();
    if (!d->context) {
        m_error = "no current OpenGL context";
        return false;
    }
    if (!d->initializeOpenGLFunctions()) {
        m_error = "OpenGL 3.3 core functions are not available";
        return false;
    }
    if (!d->surfaceProgram.addShaderFromSourceCode(QOpenGLShader::Vertex, kSurfaceVertexShader) ||
        !d->surfaceProgram.addShaderFromSourceCode(QOpenGLShader::Fragment,
                                                   kSurfaceFragmentShader) ||
        !d->surfaceProgram.link()) {
        m_error = d->surfaceProgram.log().toStdString();
        return false;
    }
    if (!d->lineProgram.addShaderFromSourceCode(QOpenGLShader::Vertex, kLineVertexShader) ||
        !d->lineProgram.addShaderFromSourceCode(QOpenGLShader::Fragment, kLineFragmentShader) ||
        !d->lineProgram.link()) {
        m_error = d->lineProgram.log().toStdString();
        return false;
    }
    d->glGenVertexArrays(1, &d->lineVao);
    d->glBindVertexArray(d->lineVao);
    d->glGenBuffers(1, &d->lineBuffer);
    d->glBindBuffer(GL_ARRAY_BUFFER, d->lineBuffer);
    d->glEnableVertexAttribArray(0);
    d->glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    d->glBindVertexArray(0);
    return true;
}

void Renderer::releaseResources()
{
    if (!d->context) return;
    for (auto& [mesh, gpu] : d->meshes)
        d->deleteMesh(gpu);
    for (auto& [id, gpu] : d->hoses)
        d->deleteHose(gpu);
    d->meshes.clear();
    d->hoses.clear();
    d->glDeleteVertexArrays(1, &d->lineVao);
    d->glDeleteBuffers(1, &d->lineBuffer);
    d->lineVao = d->lineBuffer = 0;
    d->surfaceProgram.removeAllShaders();
    d->lineProgram.removeAllShaders();
    d->context = nullptr;
}

std::vector<Vec3> Renderer::kinkRing(const Vec3& centre, const Vec3& normal, double radius)
{
    const Vec3 n = normal.normalized();
    const Vec3 u = n.unitOrthogonal();
    const Vec3 v = n.cross(u);
    std::vector<Vec3> ring;
    constexpr int kSegments = 24;
    for (int i = 0; i <= kSegments; ++i) {
        const double angle = 2.0 * 3.14159265358979323846 * (i % kSegments) / kSegments;
        ring.push_back(centre + radius * (std::cos(angle) * u + std::sin(angle) * v));
    }
    return ring;
}

QColor Renderer::partColour(const formats::ImportedScene& scene, int node)
{
    static const QColor palette[8] = {
        QColor(150, 156, 166), // steel grey
        QColor(214, 178, 112), // brass
        QColor(118, 160, 112), // sage green
        QColor(196, 132, 96),  // copper
        QColor(170, 150, 200), // lavender
        QColor(204, 196, 120), // olive yellow
        QColor(112, 150, 150), // teal grey
        QColor(190, 120, 150), // mauve
    };
    int k = 0;
    for (int n = 0; n < node && n < static_cast<int>(scene.nodes.size()); ++n)
        if (!scene.nodes[static_cast<size_t>(n)].meshes.empty()) ++k;
    return palette[k % 8];
}

double Renderer::gizmoLength(const Camera& camera)
{
    return 0.18 * camera.distance;
}

double Renderer::gizmoRingRadius(const Camera& camera)
{
    return 0.65 * gizmoLength(camera);
}

std::vector<Vec3> Renderer::gizmoRing(const Vec3& centre, int axis, double radius, int segments)
{
    const Vec3 u = Vec3::Unit((axis + 1) % 3);
    const Vec3 v = Vec3::Unit((axis + 2) % 3);
    std::vector<Vec3> ring;
    ring.reserve(static_cast<size_t>(segments) + 1);
    for (int i = 0; i <= segments; ++i) {
        const double angle = 2.0 * 3.14159265358979323846 * (i % segments) / segments;
        ring.push_back(centre + radius * (std::cos(angle) * u + std::sin(angle) * v));
    }
    return ring;
}

void Renderer::render(const Document& document, const Camera& camera, int width, int height,
                      const RenderOptions& options)
{
    m_stats = RenderStats();
    Private& gl = *d;
    gl.glViewport(0, 0, width, height);
    gl.glClearColor(float(options.background.redF()), float(options.background.greenF()),
                    float(options.background.blueF()), 1.0f);
    gl.glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl.glEnable(GL_DEPTH_TEST);
    gl.glDisable(GL_CULL_FACE);
    gl.glEnable(GL_PROGRAM_POINT_SIZE);
    gl.glPolygonMode(GL_FRONT_AND_BACK, options.wireframe ? GL_LINE : GL_FILL);

    // State a QPainter drawing over the last frame may have left (the viewport's labels).
    gl.glDepthMask(GL_TRUE);
    gl.glDisable(GL_BLEND);
    gl.glDisable(GL_SCISSOR_TEST);
    gl.glDisable(GL_STENCIL_TEST);
    const Eigen::Matrix4f viewProjection =
        toFloat(camera.projection(double(width) / std::max(height, 1)) * camera.view());
    const Vec3 eye = camera.eye();
    const Selection& selection = document.selection();

    for (auto& [mesh, gpu] : gl.meshes)
        gpu.used = false;
    for (auto& [id, gpu] : gl.hoses)
        gpu.used = false;

    gl.surfaceProgram.bind();
    gl.glUniformMatrix4fv(gl.surfaceProgram.uniformLocation("viewProjection"), 1, GL_FALSE,
                          viewProjection.data());
    gl.surfaceProgram.setUniformValue("eye",
                                      QVector3D(float(eye.x()), float(eye.y()), float(eye.z())));
    const int modelLocation = gl.surfaceProgram.uniformLocation("model");
    const int normalLocation = gl.surfaceProgram.uniformLocation("normalMatrix");

    // Scene meshes.
    for (const auto& [sceneId, scene] : document.scenes()) {
        // Nodes under the selected node are tinted.
        std::vector<char> selected(scene.nodes.size(), 0);
        for (size_t n = 0; n < scene.nodes.size(); ++n) {
            const int parent = scene.nodes[n].parent;
            selected[n] = (sceneId == selection.sceneId && int(n) == selection.node) ||
                          (parent >= 0 && selected[static_cast<size_t>(parent)]);
        }
        for (size_t n = 0; n < scene.nodes.size(); ++n) {
            const formats::SceneNode& node = scene.nodes[n];
            if (node.meshes.empty()) continue;
            const Eigen::Matrix4d world = document.nodeWorldTransform(sceneId, int(n));
            const Eigen::Matrix4f model = toFloat(world);
            const Eigen::Matrix3f normalMatrix =
                world.block<3, 3>(0, 0).inverse().transpose().cast<float>();
            gl.glUniformMatrix4fv(modelLocation, 1, GL_FALSE, model.data());
            gl.glUniformMatrix3fv(normalLocation, 1, GL_FALSE, normalMatrix.data());
            gl.surfaceProgram.setUniformValue("colour", partColour(scene, int(n)));
            gl.surfaceProgram.setUniformValue("highlight", selected[n] ? 1.0f : 0.0f);
            gl.surfaceProgram.setUniformValue("roughness", 0.6f);
            for (int meshIndex : node.meshes) {
                const formats::SceneMesh& mesh = scene.meshes[static_cast<size_t>(meshIndex)];
                if (mesh.indices.empty()) continue;
                Private::GpuMesh& gpu = gl.meshFor(mesh);
                gl.glBindVertexArray(gpu.vao);
                gl.glDrawElements(GL_TRIANGLES, gpu.indexCount, GL_UNSIGNED_INT, nullptr);
                m_stats.trianglesDrawn += gpu.indexCount / 3;
            }
        }
    }

    // Hoses.
    for (const formats::HoseDefinition& definition : document.project().hoses) {
        const Hose* hose = document.hose(definition.id);
        if (!hose) continue;
        gl.surfaceProgram.bind();
        const auto updateStart = std::chrono::steady_clock::now();
        Private::GpuHose& gpu =
            gl.hoseFor(document, definition.id, *hose, options.showProblems, m_stats);
        m_stats.hoseUpdateMilliseconds += std::chrono::duration<double, std::milli>(
                                              std::chrono::steady_clock::now() - updateStart)
                                              .count();
        Eigen::Matrix4d model = Eigen::Matrix4d::Identity();
        model.block<3, 1>(0, 3) = hose->origin();
        const Eigen::Matrix4f modelFloat = toFloat(model);
        const Eigen::Matrix3f identity = Eigen::Matrix3f::Identity();
        gl.glUniformMatrix4fv(modelLocation, 1, GL_FALSE, modelFloat.data());
        gl.glUniformMatrix3fv(normalLocation, 1, GL_FALSE, identity.data());
        gl.surfaceProgram.setUniformValue("colour", linearToDisplay(definition.colour));
        gl.surfaceProgram.setUniformValue("highlight",
                                          definition.id == selection.hoseId ? 1.0f : 0.0f);
        gl.surfaceProgram.setUniformValue("roughness", float(definition.roughness));
        gl.glBindVertexArray(gpu.vao);
        gl.glDrawElements(GL_TRIANGLES, gpu.indexCount, GL_UNSIGNED_INT, nullptr);
        gl.glBindVertexArray(0);
        m_stats.trianglesDrawn += gpu.indexCount / 3;
        ++m_stats.hosesDrawn;
    }
    gl.glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);

    // Overlays: drawn without depth test so they stay visible through the hose.
    gl.glDisable(GL_DEPTH_TEST);
    if (document.hoseDefinition(selection.hoseId)) {
        if (const Hose* hose = document.hose(selection.hoseId)) {
            const std::vector<Vec3> axis = hose->points();
            gl.drawLines(axis, GL_POINTS, QColor(255, 255, 255), 5.0f, viewProjection);
            std::vector<Vec3> fixed;
            for (int i = 0; i < hose->pointCount(); ++i)
                if (hose->isFixed(i)) fixed.push_back(axis[static_cast<size_t>(i)]);
            gl.drawLines(fixed, GL_POINTS, QColor(60, 200, 255), 9.0f, viewProjection);
            if (selection.rangeFirst >= 0 && selection.rangeLast < hose->pointCount()) {
                std::vector<Vec3> range(axis.begin() + selection.rangeFirst,
                                        axis.begin() + selection.rangeLast + 1);
                gl.drawLines(range, GL_POINTS, QColor(255, 120, 20), 11.0f, viewProjection);
            }
        }
        // The route where the parts the hose is fixed to have carried it.
        const std::vector<Vec3> route = document.displayRoute(selection.hoseId);
        gl.drawLines(route, GL_LINE_STRIP, QColor(250, 220, 60, 255), 1.0f, viewProjection);
        gl.drawLines(route, GL_POINTS, QColor(250, 220, 60), 10.0f, viewProjection);
        if (selection.routePoint >= 0 && selection.routePoint < static_cast<int>(route.size()))
            gl.drawLines({route[static_cast<size_t>(selection.routePoint)]}, GL_POINTS,
                         QColor(255, 255, 255), 14.0f, viewProjection);
    }
    {
        // Clips: a ring around the hose where each holds it, across the clip's axis.
        const QColor clipColour(235, 90, 235);
        for (const formats::HoseDefinition& definition : document.project().hoses) {
            const Hose* hose = document.hose(definition.id);
            if (!hose) continue;
            for (const Hose::Attachment& clip : hose->attachments()) {
                if (!clip.isClip()) continue;
                const std::vector<Vec3> ring =
                    kinkRing(clip.frame.apply(clip.clipCentre), clip.frame.rotation * clip.clipAxis,
                             2.2 * hose->outerRadius());
                gl.drawLines(ring, GL_LINE_STRIP, clipColour, 3.0f, viewProjection);
            }
        }
    }
    if (options.showProblems) {
        // What a hose cannot do, drawn where it happens (problem red, the Problems panel's
        // colour): the gap between an attachment the hose cannot reach and where its part
        // wants it, and a ring around each kinked joint.
        const QColor problem(255, 70, 60);
        const Vec3 towardsViewer = -camera.forward();
        for (const formats::HoseDefinition& definition : document.project().hoses) {
            const Hose* hose = document.hose(definition.id);
            const HoseMetrics* metrics = hose ? document.hoseMetrics(definition.id) : nullptr;
            if (!metrics) continue;
            for (const HoseMetrics::UnmetAttachment& unmet : metrics->unmetAttachments)
                for (const Hose::Attachment& attachment : hose->attachments()) {
                    if (attachment.id != unmet.id) continue;
                    std::vector<Vec3> gap, targets;
                    for (int i = attachment.first; i <= attachment.last; ++i) {
                        const Vec3 target = attachment.frame.apply(
                            attachment.localPoints[static_cast<size_t>(i - attachment.first)]);
                        gap.push_back(hose->point(i));
                        gap.push_back(target);
                        targets.push_back(target);
                    }
                    gl.drawLines(gap, GL_LINES, problem, 1.0f, viewProjection);
                    gl.drawLines(targets, GL_POINTS, problem, 11.0f, viewProjection);
                }
            std::vector<int> kinks = metrics->bendBelowMinimum;
            if (kinks.empty() && metrics->angleViolation > 1e-6)
                kinks.push_back(metrics->angleViolationJoint);
            for (int joint : kinks) {
                const std::vector<Vec3> ring =
                    kinkRing(hose->point(joint), towardsViewer, 2.5 * hose->outerRadius());
                gl.drawLines(ring, GL_LINE_STRIP, problem, 1.0f, viewProjection);
                gl.drawLines(ring, GL_POINTS, problem, 3.0f, viewProjection);
            }
        }
    }
    if (options.showProblems) {
        // Clearance violations: a line from the hose surface to the object, dots at both ends.
        for (const ClearanceMarker& marker : document.clearanceMarkers()) {
            gl.drawLines({marker.onHose, marker.onObject}, GL_LINES, QColor(255, 170, 40), 1.0f,
                         viewProjection);
            gl.drawLines({marker.onHose, marker.onObject}, GL_POINTS, QColor(255, 170, 40), 9.0f,
                         viewProjection);
        }
    }
    {
        // Sockets: a ring of the capture radius across the socket's axis, its centre and the
        // axis out of the part (one capture radius long); the selected socket brighter.
        for (const formats::Socket& socket : document.project().sockets) {
            Vec3 centre, axis;
            if (!document.socketWorld(socket, &centre, &axis)) continue;
            const bool selected = socket.id == selection.socketId;
            const QColor colour = selected ? QColor(255, 255, 120) : QColor(60, 220, 220);
            const std::vector<Vec3> ring = kinkRing(centre, axis, socket.captureRadius);
            gl.drawLines(ring, GL_LINE_STRIP, colour, selected ? 3.0f : 2.0f, viewProjection);
            const Vec3 tip = centre + socket.captureRadius * axis;
            gl.drawLines({centre, tip}, GL_LINES, colour, 2.0f, viewProjection);
            gl.drawLines({centre}, GL_POINTS, colour, selected ? 11.0f : 8.0f, viewProjection);
        }
    }
    if (!options.pendingRoute.empty()) {
        gl.drawLines(options.pendingRoute, GL_LINE_STRIP, QColor(120, 255, 140), 1.0f,
                     viewProjection);
        gl.drawLines(options.pendingRoute, GL_POINTS, QColor(120, 255, 140), 10.0f, viewProjection);
    }
    if (options.showGizmo && document.scene(selection.sceneId) && selection.node >= 0) {
        const Frame frame = document.nodeWorldFrame(selection.sceneId, selection.node);
        const double length = gizmoLength(camera);
        const QColor colours[3] = {QColor(235, 60, 60), QColor(80, 220, 80), QColor(70, 120, 255)};
        for (int axis = 0; axis < 3; ++axis) {
            const Vec3 tip = frame.translation + length * Vec3::Unit(axis);
            const QColor colour =
                axis == options.activeGizmoAxis ? QColor(255, 255, 80) : colours[axis];
            gl.drawLines({frame.translation, tip}, GL_LINES, colour, 1.0f, viewProjection);
            gl.drawLines({tip}, GL_POINTS, colour, 12.0f, viewProjection);
        }
        // Rotate rings, one per axis; dotted with small points so they read thicker than the
        // one-pixel lines a core profile allows.
        const double radius = gizmoRingRadius(camera);
        for (int axis = 0; axis < 3; ++axis) {
            const QColor colour =
                axis == options.activeGizmoRing ? QColor(255, 255, 80) : colours[axis];
            const std::vector<Vec3> ring = gizmoRing(frame.translation, axis, radius);
            gl.drawLines(ring, GL_LINE_STRIP, colour, 1.0f, viewProjection);
            gl.drawLines(ring, GL_POINTS, colour, axis == options.activeGizmoRing ? 4.0f : 3.0f,
                         viewProjection);
        }
    }
    gl.glEnable(GL_DEPTH_TEST);

    // Drop GPU copies of meshes and hoses that no longer exist.
    for (auto it = gl.meshes.begin(); it != gl.meshes.end();) {
        if (!it->second.used) {
            gl.deleteMesh(it->second);
            it = gl.meshes.erase(it);
        } else {
            ++it;
        }
    }
    for (auto it = gl.hoses.begin(); it != gl.hoses.end();) {
        if (!it->second.used) {
            gl.deleteHose(it->second);
            it = gl.hoses.erase(it);
        } else {
            ++it;
        }
    }
}

} // namespace chaintube::editor
