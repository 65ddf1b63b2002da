// The chain projection: bounded Newton steps that bring a range of a hose's axis points onto
// its constraints. Internal to lib/ (solver.cpp, sag.cpp).
#pragma once

#include "chaintube/hose.h"

#include <cstdint>
#include <tuple>
#include <vector>

namespace chaintube::detail {

/// What one ChainProjection::run() did.
struct ProjectionOutcome
{
    bool converged = false; ///< every active constraint within the tolerance
    int iterations = 0;     ///< Newton steps taken (each O(points in the range))
    double violation =
        0.0; ///< largest violation left: relative length, radians, contact depth / mean rest
};

/// Projects axis points first … last of a hose onto its constraints: every segment inside its
/// stretch band, every joint within its deflection limit, every point with a contact plane at
/// least its distance above it. Points with inverse mass 0 stay where they are (attachments,
/// a held point); the others move in proportion to their inverse mass.
///
/// Each step linearises the active constraints at the current positions x and solves
///   (J W Jᵀ + D) λ = −C(x),   x ← x + W Jᵀ λ
/// with W the inverse masses and D the compliance of soft rows (0 for hard ones): the minimal
/// move onto the linearised constraints, converging quadratically to a feasible point (a
/// gravity step writes its predicted positions into the hose and projects from there: the
/// fast projection of Goldenthal et al. 2007). A constraint touches at most three consecutive
/// points, so J W Jᵀ is banded (half-bandwidth ≤ 8) and one step costs O(last − first) through
/// a banded LDLᵀ; a range of lengths alone is tridiagonal (lengthsOnly()). Inequalities
/// (stretch bands, bend limits, contacts) are handled by a working set
/// kept from Newton step to Newton step (Hose::m_workingSet): rows on their bound
/// are held there, rows whose multiplier pulls leave it, rows the step would violate join it
/// (up to four solves of one linearisation). Deterministic; never produces NaN or Inf (a
/// non-finite step is not taken).
/// A row of the linearised system: one constraint on 1 … 3 consecutive points.
struct ProjectionRow
{
    int first = 0;                                          ///< first point
    int count = 0;                                          ///< 1 … 3 consecutive points
    Vec3 g[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}; ///< gradient per point
    double value = 0.0;                                     ///< C(x): 0 on the bound, > 0 violated
    double compliance = 0.0; ///< added to the diagonal (relative, see setBendCompliance)
    size_t key = 0;          ///< 3 · point + kind (contact, length, bend): Hose::m_workingSet
    signed char side = 0;    ///< length rows: +1 upper bound, −1 lower bound
    bool inequality = false;
    bool working = false; ///< held on its bound in this step
};

/// ChainProjection's vectors, kept in the hose's workspace between projections (each
/// projection starts with them empty, as if new).
struct ProjectionBuffers
{
    std::vector<double> m_inverseMass;
    std::vector<unsigned char> m_hasContact;
    std::vector<Vec3> m_contactNormal, m_contactPoint;
    std::vector<double> m_contactDistance;
    std::vector<ProjectionRow> m_rows;
    std::vector<double> m_system, m_systemRhs; ///< buildSystem(): band (m_width a row), rhs
    std::vector<double> m_band, m_lambda;      ///< solveWorking(): factor, multipliers (per row)
    std::vector<unsigned char> m_working;      ///< solveWorking(): per row, in the working set
    std::vector<Vec3> m_step, m_saved;
    std::vector<Vec3> m_unit; ///< gatherLengths(): per segment of the range, its unit direction
    void clear();
    /// Exchanges every vector with `other`'s (their storage, no element moved).
    void swap(ProjectionBuffers& other) noexcept;

private:
    auto vectors()
    {
        return std::tie(m_inverseMass, m_hasContact, m_contactNormal, m_contactPoint,
                        m_contactDistance, m_rows, m_system, m_systemRhs, m_band, m_lambda,
                        m_working, m_step, m_saved, m_unit);
    }
};

class ChainProjection : private ProjectionBuffers
{
public:
    /// Takes the hose's projection buffers for its lifetime (a projection made while another
    /// one holds them starts with its own).
    explicit ChainProjection(Hose& hose);
    ~ChainProjection();
    ChainProjection(const ChainProjection&) = delete;
    ChainProjection& operator=(const ChainProjection&) = delete;

    /// Range of points taking part (inclusive). Rows touching only points outside it, or only
    /// points of inverse mass 0, are left out; points outside it count as fixed.
    void setRange(int first, int last);
    /// Inverse mass per point (size pointCount(); 0 = fixed). Default: mass from the adjacent
    /// rest lengths, attachments and `held` fixed.
    void useMassesFromRestLengths(int held);
    std::vector<double>& inverseMass() { return m_inverseMass; }
    /// Bend rows soft with this compliance relative to their diagonal (0: hard). Soft bends
    /// give way to the lengths: the result violates them as little as it can in the least
    /// squares sense.
    void setBendCompliance(double relative) { m_bendCompliance = relative; }
    /// Whether bend rows take part at all (false: the lengths and contacts alone; the bends
    /// are then neither corrected nor counted in the violation).
    void setBends(bool on) { m_bends = on; }
    /// Contact planes: point i keeps normal · (p_i − onPlane) ≥ distance (local coordinates).
    void clearContacts();
    void setContact(int point, const Vec3& normal, const Vec3& onPlane, double distance);
    /// The contact of `point` with a collider's surface at `closest` (world coordinates; the
    /// hose's origin is `origin`): its tangent plane, turned towards `cameFrom` (local) when
    /// the point lies on the surface to within `onSurface`. Returns false, setting nothing, if
    /// the normal is not finite.
    bool setContact(int point, const MeshCollider::Closest& closest, const Vec3& origin,
                    const Vec3& cameFrom, double distance, double onSurface);

    /// At most maxIterations steps, stopping when the largest violation is ≤ tolerance.
    ProjectionOutcome run(int maxIterations, double tolerance);

    /// Largest violation of the rows in the range at the current positions (as run() reports).
    double violation();

private:
    using Row = ProjectionRow;
    /// Gathers the candidate rows at the current positions (violated, near their bound, or in
    /// the working set); returns the largest violation.
    double gather(bool onlyMeasure);
    /// Whether the range's constraints are its segments' lengths alone, each held at one length
    /// (no contacts, no joint limited, no stretch band): the system is then tridiagonal, its
    /// rows always working, and run() takes gatherLengths() and solveLengths() instead of the
    /// rows.
    bool lengthsOnly() const;
    /// gather() of a lengths-only range: the segments' unit directions and violations, no rows.
    double gatherLengths();
    /// buildSystem() and solveWorking() of a lengths-only range: one tridiagonal LDLᵀ solve.
    bool solveLengths();
    /// Whether segment first + j has a row in the lengths-only system (not both its points
    /// fixed, a length to take a direction from), after gatherLengths().
    bool hasLengthRow(size_t j) const
    {
        const size_t k = static_cast<size_t>(m_first) + j;
        return m_inverseMass[k] + m_inverseMass[k + 1] > 0.0 && m_unit[j].squaredNorm() > 0.0;
    }
    /// The linearised system of every gathered row at the current positions (built once a
    /// Newton step; the working-set passes reuse it).
    void buildSystem();
    /// Solves for the working rows' multipliers and the step; false if not finite. After a
    /// change of the working set (adjustWorkingSet()), a band of width 7 or more (contacts) is
    /// factored again only where the change reaches (resolveBandedLdltTwisted: the same result).
    bool solveWorking();
    /// One primal-dual update of the working set after solveWorking(): rows whose multiplier
    /// pulls leave, rows the step would violate join. Returns whether it changed.
    bool adjustWorkingSet();

    Hose& h;
    int m_first = 0;
    int m_last = -1;
    double m_meanRest = 1.0;
    double m_bendCompliance = 0.0;
    bool m_bends = true;
    size_t m_width = 1;
    double m_merit = 0.0;       ///< gather(): sum of the squared violations
    double m_damping = 0.0;     ///< Levenberg–Marquardt damping, relative to the diagonal
    double m_joinMargin = 1e-9; ///< run(): adjustWorkingSet()'s margin for rows that join
    bool m_factored = false;    ///< m_band holds the factor of this linearisation's last solve
    size_t m_changedFirst = 0;  ///< adjustWorkingSet(): first and last row it changed
    size_t m_changedLast = 0;
};

} // namespace chaintube::detail
