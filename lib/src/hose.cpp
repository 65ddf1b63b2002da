#include "chaintube/hose.h"

#include "chaintube/route.h"
#include "workspace.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>

namespace chaintube {

namespace detail {

WorkspaceSlot::WorkspaceSlot() noexcept = default;
WorkspaceSlot::~WorkspaceSlot() = default;
WorkspaceSlot::WorkspaceSlot(const WorkspaceSlot&) noexcept {}
WorkspaceSlot& WorkspaceSlot::operator=(const WorkspaceSlot&) noexcept
{
    return *this; // the buffers are not state: each hose keeps its own
}
WorkspaceSlot::WorkspaceSlot(WorkspaceSlot&&) noexcept = default;
WorkspaceSlot& WorkspaceSlot::operator=(WorkspaceSlot&&) noexcept = default;

Workspace& WorkspaceSlot::get()
{
    if (!m_workspace) m_workspace = std::make_unique<Workspace>();
    return *m_workspace;
}

} // namespace detail

namespace {
constexpr int kMaxSegments = 1000000;

std::string str(double value)
{
    std::ostringstream out;
    out.precision(17);
    out << value;
    return out.str();
}

std::string str(const Vec3& v)
{
    return "(" + str(v.x()) + ", " + str(v.y()) + ", " + str(v.z()) + ")";
}

HoseSpec withDefaultProfile(HoseSpec spec)
{
    if (spec.profile.vertexCount() == 0)
        spec.profile = Profile::circle(0.5 * spec.outerDiameter, 16);
    return spec;
}

int segmentsFor(const HoseSpec& spec, double length)
{
    if (spec.segmentCount > 0) return spec.segmentCount;
    const double count = std::round(length / spec.segmentLength);
    if (!(count <= kMaxSegments))
        throw InvalidArgument("hose.segmentLength: " + str(spec.segmentLength) +
                              " m gives more than " + std::to_string(kMaxSegments) +
                              " segments for a " + str(length) + " m hose");
    return std::max(1, static_cast<int>(count));
}
} // namespace

const char* toString(Status status)
{
    switch (status) {
    case Status::Ok:
        return "ok";
    case Status::Clamped:
        return "clamped";
    case Status::Infeasible:
        return "infeasible";
    case Status::InvalidInput:
        return "invalid input";
    }
    return "unknown";
}

void HoseSpec::validate() const
{
    if (!std::isfinite(outerDiameter) || outerDiameter <= 0.0)
        throw InvalidArgument("hose.outerDiameter: expected a length > 0 m, got " +
                              str(outerDiameter));
    material.validate();
    if (segmentCount < 0 || segmentCount > kMaxSegments)
        throw InvalidArgument("hose.segmentCount: expected 1 … " + std::to_string(kMaxSegments) +
                              " (or 0 to use segmentLength), got " + std::to_string(segmentCount));
    if (segmentCount == 0 && (!std::isfinite(segmentLength) || segmentLength <= 0.0))
        throw InvalidArgument("hose.segmentLength: expected a length > 0 m, got " +
                              str(segmentLength));
    if (!gravity.direction.allFinite() || gravity.direction.squaredNorm() == 0.0)
        throw InvalidArgument("hose.gravity.direction: expected a finite non-zero vector, got " +
                              str(gravity.direction));
    if (!std::isfinite(torsion.twistLimit) || torsion.twistLimit <= 0.0 ||
        torsion.twistLimit > std::numbers::pi)
        throw InvalidArgument(
            "hose.torsion.twistLimit: expected an angle in (0, pi] rad per joint, got " +
            str(torsion.twistLimit));
}

Hose Hose::straight(const Vec3& start, const Vec3& direction, double length, const HoseSpec& spec)
{
    spec.validate();
    if (!start.allFinite())
        throw InvalidArgument("hose.start: expected finite coordinates, got " + str(start));
    if (!direction.allFinite() || !(direction.norm() > 0.0))
        throw InvalidArgument("hose.direction: expected a finite non-zero vector, got " +
                              str(direction));
    if (!std::isfinite(length) || length <= 0.0)
        throw InvalidArgument("hose.length: expected a length > 0 m, got " + str(length));
    const int segments = segmentsFor(spec, length);
    const Vec3 unit = direction.normalized();
    std::vector<Vec3> axis;
    axis.reserve(static_cast<size_t>(segments) + 1);
    for (int i = 0; i <= segments; ++i)
        axis.push_back(start + unit * (length * i / segments));
    Hose hose;
    hose.initialiseFromAxis(axis, spec);
    return hose;
}

Hose Hose::alongRoute(const std::vector<Vec3>& route, const HoseSpec& spec)
{
    spec.validate();
    if (route.size() < 2)
        throw InvalidArgument("hose.route: expected at least 2 points, got " +
                              std::to_string(route.size()));
    for (size_t i = 0; i < route.size(); ++i) {
        if (!route[i].allFinite())
            throw InvalidArgument("hose.route[" + std::to_string(i) +
                                  "]: expected finite coordinates");
        if (i > 0 && !((route[i] - route[i - 1]).norm() > 0.0))
            throw InvalidArgument("hose.route[" + std::to_string(i) +
                                  "]: repeats the previous point " + str(route[i]));
    }
    const double rawLength = polylineLength(route);
    const double nominalSegment =
        spec.segmentCount > 0 ? rawLength / spec.segmentCount : spec.segmentLength;
    double radius = 0.0;
    if (spec.material.bendLimit.kind == BendLimit::Kind::MinBendRadius) {
        radius = spec.material.bendLimit.value;
    } else {
        radius = bendRadiusOfTurn(nominalSegment, spec.material.bendLimit.value);
    }
    // A 0.1 % larger arc, sampled finely, keeps the resampled chords inside the bend limit.
    radius = std::min(radius * 1.001, 1e3 * rawLength); // arcs are limited by the legs anyway
    const std::vector<Vec3> rounded =
        filletRoute(route, radius, std::max(nominalSegment / 32.0, 1e-9 * rawLength));
    const double length = polylineLength(rounded);
    const std::vector<Vec3> axis = resampleByArcLength(rounded, segmentsFor(spec, length));
    Hose hose;
    hose.initialiseFromAxis(axis, spec);
    return hose;
}

Hose Hose::fromAxis(const std::vector<Vec3>& axisPoints, const HoseSpec& spec)
{
    spec.validate();
    Hose hose;
    hose.initialiseFromAxis(axisPoints, spec);
    return hose;
}

Hose Hose::fromAxis(const std::vector<Vec3>& axisPoints, const std::vector<double>& restLengths,
                    const HoseSpec& spec)
{
    spec.validate();
    Hose hose;
    hose.initialiseFromAxis(axisPoints, spec);
    if (restLengths.size() != hose.m_restLength.size())
        throw InvalidArgument(
            "hose.restLengths: expected " + std::to_string(hose.m_restLength.size()) +
            " values (one per segment), got " + std::to_string(restLengths.size()));
    for (size_t s = 0; s < restLengths.size(); ++s)
        if (!std::isfinite(restLengths[s]) || restLengths[s] <= 0.0)
            throw InvalidArgument("hose.restLengths[" + std::to_string(s) +
                                  "]: expected a length > 0 m, got " + str(restLengths[s]));
    hose.m_restLength = restLengths;
    hose.recomputeLimits();
    hose.m_dirtyViolation = hose.measureViolation().status != Status::Ok;
    return hose;
}

void Hose::initialiseFromAxis(const std::vector<Vec3>& axisPoints, const HoseSpec& spec)
{
    if (axisPoints.size() < 2)
        throw InvalidArgument("hose.axis: expected at least 2 points, got " +
                              std::to_string(axisPoints.size()));
    if (axisPoints.size() > static_cast<size_t>(kMaxSegments) + 1)
        throw InvalidArgument("hose.axis: at most " + std::to_string(kMaxSegments + 1) +
                              " points, got " + std::to_string(axisPoints.size()));
    double total = 0.0;
    for (size_t i = 0; i < axisPoints.size(); ++i) {
        if (!axisPoints[i].allFinite())
            throw InvalidArgument("hose.axis[" + std::to_string(i) +
                                  "]: expected finite coordinates");
        if (i > 0) total += (axisPoints[i] - axisPoints[i - 1]).norm();
    }
    m_spec = withDefaultProfile(spec);
    m_origin = axisPoints.front();
    m_local.resize(axisPoints.size());
    for (size_t i = 0; i < axisPoints.size(); ++i)
        m_local[i] = axisPoints[i] - m_origin;
    const size_t segments = axisPoints.size() - 1;
    m_restLength.resize(segments);
    for (size_t s = 0; s < segments; ++s) {
        m_restLength[s] = (m_local[s + 1] - m_local[s]).norm();
        if (!(m_restLength[s] > 1e-12 * total))
            throw InvalidArgument("hose.axis[" + std::to_string(s + 1) +
                                  "]: coincides with the previous point (segments need a length)");
    }
    m_fixed.assign(axisPoints.size(), 0);
    m_attachments.clear();
    recomputeLimits();
    m_dirtyViolation = measureViolation().status != Status::Ok;
    ++m_revision;
}

void Hose::recomputeLimits()
{
    const size_t segments = m_restLength.size();
    const double e = m_spec.material.expansionCoefficient;
    m_minLength.resize(segments);
    m_maxLength.resize(segments);
    m_minLengthBefore.assign(segments + 1, 0.0);
    for (size_t s = 0; s < segments; ++s) {
        m_minLength[s] = m_restLength[s] * (1.0 - e);
        m_maxLength[s] = m_restLength[s] * (1.0 + e);
        m_minLengthBefore[s + 1] = m_minLengthBefore[s] + m_minLength[s];
    }
    const size_t points = m_local.size();
    m_cosLimit.assign(points, -1.0);
    m_sinLimit.assign(points, 0.0);
    m_limitAngle.assign(points, std::atan2(0.0, -1.0));
    m_cosHalfLimit.assign(points, 0.0);
    m_sinHalfLimit.assign(points, 1.0);
    m_chordLimit2.assign(points, 4.0 + 1e-9);
    for (size_t j = 1; j + 1 < points; ++j) {
        const double mean = 0.5 * (m_restLength[j - 1] + m_restLength[j]);
        const double limit = jointDeflectionLimit(m_spec.material.bendLimit, mean);
        m_cosLimit[j] = std::cos(limit);
        m_sinLimit[j] = std::sin(limit);
        m_limitAngle[j] = std::atan2(m_sinLimit[j], m_cosLimit[j]);
        m_cosHalfLimit[j] = std::cos(0.5 * limit);
        m_sinHalfLimit[j] = std::sin(0.5 * limit);
        // Squared chord between unit directions turning by the limit, 4 sin²(θ/2), plus
        // 1e-12 rad of tolerance (d chord² / dθ = 2 sin θ ≤ 2θ).
        m_chordLimit2[j] = 4.0 * m_sinHalfLimit[j] * m_sinHalfLimit[j] + 2e-12 * limit + 1e-24;
    }
}

std::vector<Vec3> Hose::points() const
{
    std::vector<Vec3> out(m_local.size());
    for (size_t i = 0; i < m_local.size(); ++i)
        out[i] = m_origin + m_local[i];
    return out;
}

double Hose::restLengthTotal() const
{
    double total = 0.0;
    for (double l : m_restLength)
        total += l;
    return total;
}

double Hose::currentLength() const
{
    double total = 0.0;
    for (size_t i = 1; i < m_local.size(); ++i)
        total += (m_local[i] - m_local[i - 1]).norm();
    return total;
}

double Hose::deflectionLimit(int joint) const
{
    if (joint <= 0 || joint >= pointCount() - 1) return std::numbers::pi;
    return m_limitAngle[static_cast<size_t>(joint)];
}

void Hose::setMaterial(const Material& material)
{
    material.validate();
    m_spec.material = material;
    recomputeLimits();
    m_dirtyViolation = measureViolation().status != Status::Ok;
    ++m_revision;
}

void Hose::setProfile(const Profile& profile)
{
    if (profile.vertexCount() == 0)
        throw InvalidArgument("hose.profile: expected a non-empty profile");
    m_spec.profile = profile;
    ++m_revision;
}

void Hose::setOuterDiameter(double metres)
{
    if (!std::isfinite(metres) || metres <= 0.0)
        throw InvalidArgument("hose.outerDiameter: expected a length > 0 m, got " + str(metres));
    m_spec.outerDiameter = metres;
    ++m_revision;
}

bool Hose::isFixed(int index) const
{
    return index >= 0 && index < pointCount() && m_fixed[static_cast<size_t>(index)] != 0;
}

int Hose::attach(int first, int last, const Frame& frame)
{
    if (first < 0 || last < first || last >= pointCount())
        throw InvalidArgument("attachment range: expected 0 <= first <= last < " +
                              std::to_string(pointCount()) + ", got " + std::to_string(first) +
                              " … " + std::to_string(last));
    if (!isFiniteFrame(frame))
        throw InvalidArgument(
            "attachment frame: expected a finite translation and a unit rotation");
    for (int i = first; i <= last; ++i)
        if (m_fixed[static_cast<size_t>(i)])
            throw InvalidArgument("attachment range " + std::to_string(first) + " … " +
                                  std::to_string(last) + ": point " + std::to_string(i) +
                                  " is already fixed by another attachment");
    Attachment attachment;
    attachment.id = m_nextAttachmentId++;
    attachment.first = first;
    attachment.last = last;
    attachment.frame = frame;
    for (int i = first; i <= last; ++i) {
        attachment.localPoints.push_back(frame.applyInverse(point(i)));
        m_fixed[static_cast<size_t>(i)] = 1;
    }
    m_attachments.push_back(std::move(attachment));
    m_edgePoint = -1; // grab(): what was the edge of reach may no longer be
    return m_attachments.back().id;
}

const Hose::Attachment* Hose::attachmentWithId(int id) const
{
    const auto it = std::find_if(m_attachments.begin(), m_attachments.end(),
                                 [id](const Attachment& a) { return a.id == id; });
    return it == m_attachments.end() ? nullptr : &*it;
}

Hose::Attachment* Hose::attachmentWithId(int id)
{
    return const_cast<Attachment*>(std::as_const(*this).attachmentWithId(id));
}

bool Hose::detach(int id)
{
    const Attachment* a = attachmentWithId(id);
    if (!a) return false;
    for (int i = a->first; i <= a->last; ++i)
        m_fixed[static_cast<size_t>(i)] = 0;
    m_attachments.erase(m_attachments.begin() + (a - m_attachments.data()));
    m_settledRevision = 0; // step(): the freed points may fall
    m_edgePoint = -1;      // grab(): what was the edge of reach may no longer be
    return true;
}

double Hose::attachmentGap(int id) const
{
    const Attachment* it = attachmentWithId(id);
    if (!it) return -1.0;
    double gap = 0.0;
    for (int i = it->first; i <= it->last; ++i)
        gap = std::max(
            gap, (it->frame.apply(it->localPoints[static_cast<size_t>(i - it->first)]) - point(i))
                     .norm());
    return gap;
}

UpdateResult Hose::moveAttachment(int id, const Frame& frame)
{
    return moveAttachments({id}, {frame});
}

} // namespace chaintube
