#include "peers.h"

#include <algorithm>
#include <chaintube/chaintube.h>
#include <cmath>
#include <limits>
#include <numbers>

#ifdef CHAINTUBE_HAVE_BULLET
#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>
#endif

namespace chaintube::bench {

namespace {

double jointLimit(const RodSetup& setup, double meanLength)
{
    if (setup.minBendRadius > 0.0)
        return jointDeflectionLimit(BendLimit::minBendRadius(setup.minBendRadius), meanLength);
    return setup.deflectionAngle;
}

// Fixed runs shared by the peers: local positions and which frame moves them.
struct FixedRuns
{
    int startCount = 0, endCount = 0;
    std::vector<Vec3> startRest, endRest;
};

class ChainTubeRod final : public RodSolver
{
public:
    explicit ChainTubeRod(const RodSetup& setup)
        : m_hose(Hose::fromAxis(setup.axis, spec(setup))), m_gravity(setup.gravity)
    {
        if (setup.floorHeight > -std::numeric_limits<double>::infinity()) {
            const double y = setup.floorHeight - m_hose.outerRadius(), far = 1e3;
            m_hose.setColliders({MeshCollider::fromArrays(
                {Vec3(-far, y, -far), Vec3(far, y, -far), Vec3(far, y, far), Vec3(-far, y, far)},
                {0, 2, 1, 0, 3, 2})});
        }
    }
    std::string name() const override { return "ChainTube"; }
    void fixStart(int count) override { m_start = m_hose.attach(0, count - 1, Frame::identity()); }
    void fixEnd(int count) override
    {
        m_end =
            m_hose.attach(m_hose.pointCount() - count, m_hose.pointCount() - 1, Frame::identity());
    }
    void step(const FrameRequest& r) override
    {
        std::vector<int> ids;
        std::vector<Frame> frames;
        if (r.moveStart) ids.push_back(m_start), frames.push_back(r.start);
        if (r.moveEnd) ids.push_back(m_end), frames.push_back(r.end);
        // The peers report no status: the results are measured from points() afterwards.
        if (!ids.empty()) static_cast<void>(m_hose.moveAttachments(ids, frames));
        for (const auto& [index, target] : r.grabs)
            static_cast<void>(m_hose.grab(index, target));
        // The runtime's per-frame gravity call: one implicit step whose velocity carries over
        // from frame to frame, as the peers' inertia does (a settled hose costs nothing).
        if (m_gravity != Vec3::Zero())
            static_cast<void>(m_hose.step()); // one implicit step a frame
    }
    std::vector<Vec3> points() const override { return m_hose.points(); }

private:
    static HoseSpec spec(const RodSetup& setup)
    {
        HoseSpec spec;
        if (setup.gravity != Vec3::Zero()) {
            spec.gravity.enabled = true;
            spec.gravity.direction = setup.gravity;
        }
        spec.material.expansionCoefficient = setup.expansionCoefficient;
        spec.material.bendLimit = setup.noBendLimit ? BendLimit::minBendRadius(0.0)
                                  : setup.minBendRadius > 0.0
                                      ? BendLimit::minBendRadius(setup.minBendRadius)
                                      : BendLimit::deflectionAngle(setup.deflectionAngle);
        return spec;
    }
    Hose m_hose;
    Vec3 m_gravity;
    int m_start = 0, m_end = 0;
};

class XpbdRod final : public RodSolver
{
public:
    XpbdRod(const RodSetup& setup, int iterations)
        : m_rest(setup.axis), m_x(setup.axis), m_iterations(iterations), m_gravity(setup.gravity),
          m_dt(setup.timeStep), m_floor(setup.floorHeight)
    {
        m_velocity.assign(m_x.size(), Vec3::Zero());
        const size_t n = m_x.size();
        m_inverseMass.assign(n, 1.0);
        for (size_t s = 0; s + 1 < n; ++s) {
            const double l = (m_x[s + 1] - m_x[s]).norm();
            m_minLength.push_back(l * (1 - setup.expansionCoefficient));
            m_maxLength.push_back(l * (1 + setup.expansionCoefficient));
        }
        m_minChord.assign(n, 0.0);
        for (size_t j = 1; j + 1 < n; ++j) {
            const double a = (m_x[j] - m_x[j - 1]).norm(), b = (m_x[j + 1] - m_x[j]).norm();
            const double turn =
                setup.noBendLimit ? std::numbers::pi : jointLimit(setup, 0.5 * (a + b));
            // Law of cosines: the neighbours' distance when the joint turns by `turn`.
            m_minChord[j] = std::sqrt(std::max(0.0, a * a + b * b + 2 * a * b * std::cos(turn)));
        }
    }
    std::string name() const override { return "XPBD x" + std::to_string(m_iterations); }
    void fixStart(int count) override
    {
        m_startCount = count;
        for (int i = 0; i < count; ++i)
            m_inverseMass[static_cast<size_t>(i)] = 0.0;
    }
    void fixEnd(int count) override
    {
        m_endCount = count;
        for (int i = 0; i < count; ++i)
            m_inverseMass[m_x.size() - 1 - static_cast<size_t>(i)] = 0.0;
    }
    void step(const FrameRequest& r) override
    {
        const size_t n = m_x.size();
        if (r.moveStart)
            for (int i = 0; i < m_startCount; ++i)
                m_x[static_cast<size_t>(i)] = r.start.apply(m_rest[static_cast<size_t>(i)]);
        if (r.moveEnd)
            for (int i = 0; i < m_endCount; ++i) {
                const size_t k = n - 1 - static_cast<size_t>(i);
                m_x[k] = r.end.apply(m_rest[k]);
            }
        std::vector<double> saved;
        for (const auto& [index, target] : r.grabs) {
            saved.push_back(m_inverseMass[static_cast<size_t>(index)]);
            m_inverseMass[static_cast<size_t>(index)] = 0.0;
            m_x[static_cast<size_t>(index)] = target;
        }
        const bool inertia = m_gravity != Vec3::Zero();
        if (inertia) {
            m_previous = m_x;
            for (size_t i = 0; i < n; ++i)
                if (m_inverseMass[i] > 0.0) {
                    m_velocity[i] += m_dt * m_gravity;
                    m_x[i] += m_dt * m_velocity[i];
                }
        }
        for (int it = 0; it < m_iterations; ++it) {
            for (size_t s = 0; s + 1 < n; ++s)
                project(s, s + 1, m_minLength[s], m_maxLength[s]);
            for (size_t j = 1; j + 1 < n; ++j)
                if (m_minChord[j] > 0.0) project(j - 1, j + 1, m_minChord[j], 1e300);
            if (m_floor > -std::numeric_limits<double>::infinity())
                for (size_t i = 0; i < n; ++i)
                    if (m_inverseMass[i] > 0.0) m_x[i].y() = std::max(m_x[i].y(), m_floor);
        }
        if (inertia)
            for (size_t i = 0; i < n; ++i)
                m_velocity[i] = (1.0 - kDamping) * (m_x[i] - m_previous[i]) / m_dt;
        for (size_t g = 0; g < r.grabs.size(); ++g)
            m_inverseMass[static_cast<size_t>(r.grabs[g].first)] = saved[g];
    }
    std::vector<Vec3> points() const override { return m_x; }

private:
    void project(size_t i, size_t k, double lower, double upper)
    {
        const double wi = m_inverseMass[i], wk = m_inverseMass[k];
        if (wi + wk == 0.0) return;
        const Vec3 d = m_x[k] - m_x[i];
        const double length = d.norm();
        if (!(length > 0.0)) return;
        const double target = std::clamp(length, lower, upper);
        if (target == length) return;
        const Vec3 correction = d * ((length - target) / (length * (wi + wk)));
        m_x[i] += wi * correction;
        m_x[k] -= wk * correction;
    }

    static constexpr double kDamping = 0.02; // velocity lost per frame (with gravity)
    std::vector<Vec3> m_rest, m_x, m_previous, m_velocity;
    std::vector<double> m_inverseMass, m_minLength, m_maxLength, m_minChord;
    int m_iterations;
    Vec3 m_gravity;
    double m_dt;
    double m_floor; // lowest axis height (RodSetup::floorHeight)
    int m_startCount = 0, m_endCount = 0;
};

#ifdef CHAINTUBE_HAVE_BULLET
class BulletRope final : public RodSolver
{
public:
    BulletRope(const RodSetup& setup, int iterations, double bendStiffness)
        : m_rest(setup.axis), m_iterations(iterations), m_dt(setup.timeStep)
    {
        m_world = std::make_unique<btSoftRigidDynamicsWorld>(
            &m_dispatcher, &m_broadphase, &m_solver, &m_configuration, &m_softSolver);
        const btVector3 gravity(setup.gravity.x(), setup.gravity.y(), setup.gravity.z());
        m_world->setGravity(gravity);
        m_info.m_gravity = gravity;
        m_info.m_broadphase = &m_broadphase;
        m_info.m_dispatcher = &m_dispatcher;
        m_info.m_sparsesdf.Initialize();
        const Vec3 a = setup.axis.front(), b = setup.axis.back();
        m_rope = btSoftBodyHelpers::CreateRope(m_info, btVector3(a.x(), a.y(), a.z()),
                                               btVector3(b.x(), b.y(), b.z()),
                                               static_cast<int>(setup.axis.size()) - 2, 0);
        for (int i = 0; i < m_rope->m_nodes.size(); ++i) {
            const Vec3& p = setup.axis[static_cast<size_t>(i)];
            m_rope->m_nodes[i].m_x = btVector3(p.x(), p.y(), p.z());
        }
        m_rope->resetLinkRestLengths(); // CreateRope spaces the nodes evenly on the chord
        m_rope->m_cfg.piterations = iterations;
        // Damping: the scenarios without gravity are quasi-static; with gravity, the same
        // 2 % per frame as the XPBD peer.
        m_rope->m_cfg.kDP = setup.gravity == Vec3::Zero() ? 0.5 : 0.02;
        m_rope->m_materials[0]->m_kLST = 1.0;
        if (!setup.noBendLimit) {
            btSoftBody::Material* bending = m_rope->appendMaterial();
            bending->m_kLST = bendStiffness;
            m_rope->generateBendingConstraints(2, bending);
        }
        m_rope->setTotalMass(1.0);
        m_world->addSoftBody(m_rope);
    }
    ~BulletRope() override
    {
        m_world->removeSoftBody(m_rope);
        delete m_rope;
    }
    std::string name() const override { return "Bullet rope x" + std::to_string(m_iterations); }
    void fixStart(int count) override
    {
        m_startCount = count;
        for (int i = 0; i < count; ++i)
            m_rope->setMass(i, 0);
    }
    void fixEnd(int count) override
    {
        m_endCount = count;
        for (int i = 0; i < count; ++i)
            m_rope->setMass(m_rope->m_nodes.size() - 1 - i, 0);
    }
    void step(const FrameRequest& r) override
    {
        const int n = m_rope->m_nodes.size();
        auto place = [&](int i, const Vec3& p) {
            m_rope->m_nodes[i].m_x = btVector3(p.x(), p.y(), p.z());
            m_rope->m_nodes[i].m_q = m_rope->m_nodes[i].m_x;
            m_rope->m_nodes[i].m_v.setZero();
        };
        if (r.moveStart)
            for (int i = 0; i < m_startCount; ++i)
                place(i, r.start.apply(m_rest[static_cast<size_t>(i)]));
        if (r.moveEnd)
            for (int i = 0; i < m_endCount; ++i)
                place(n - 1 - i, r.end.apply(m_rest[static_cast<size_t>(n - 1 - i)]));
        for (const auto& [index, target] : r.grabs) {
            if (m_rope->getMass(index) != 0) m_rope->setMass(index, 0); // kinematic from now on
            place(index, target);
        }
        m_world->stepSimulation(static_cast<btScalar>(m_dt), 0);
    }
    std::vector<Vec3> points() const override
    {
        std::vector<Vec3> out;
        for (int i = 0; i < m_rope->m_nodes.size(); ++i) {
            const btVector3& p = m_rope->m_nodes[i].m_x;
            out.emplace_back(p.x(), p.y(), p.z());
        }
        return out;
    }

private:
    std::vector<Vec3> m_rest;
    int m_iterations;
    double m_dt;
    int m_startCount = 0, m_endCount = 0;
    btSoftBodyRigidBodyCollisionConfiguration m_configuration;
    btCollisionDispatcher m_dispatcher{&m_configuration};
    btDbvtBroadphase m_broadphase;
    btSequentialImpulseConstraintSolver m_solver;
    btDefaultSoftBodySolver m_softSolver;
    std::unique_ptr<btSoftRigidDynamicsWorld> m_world;
    btSoftBodyWorldInfo m_info;
    btSoftBody* m_rope = nullptr;
};
#endif

} // namespace

std::unique_ptr<RodSolver> makeChainTubeRod(const RodSetup& setup)
{
    return std::make_unique<ChainTubeRod>(setup);
}

std::unique_ptr<RodSolver> makeXpbdRod(const RodSetup& setup, int iterations)
{
    return std::make_unique<XpbdRod>(setup, iterations);
}

#ifdef CHAINTUBE_HAVE_BULLET
std::unique_ptr<RodSolver> makeBulletRope(const RodSetup& setup, int iterations,
                                          double bendStiffness)
{
    return std::make_unique<BulletRope>(setup, iterations, bendStiffness);
}
#endif

} // namespace chaintube::bench
