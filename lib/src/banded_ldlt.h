// The banded symmetric solve of the chain projection (projection.cpp: gravity steps, contacts,
// bends giving way), of the span solver's small dense normal equations (span_solver.cpp: a band
// as wide as the matrix) and of its steps towards a held target (a block-tridiagonal band
// factored once and solved for several right-hand sides). Internal to lib/.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace chaintube::detail {

/// The LDLᵀ elimination of factorBandedLdlt, with `rhs` (b) eliminated in the same pass when
/// WithRhs (solveBandedLdlt's one pass over the band).
template <bool WithRhs>
inline std::size_t eliminateBandedLdlt(double* band, double* rhs, std::size_t m, std::size_t width)
{
    std::size_t dropped = 0;
    for (std::size_t i = 0; i < m; ++i) {
        double& pivot = band[i * width];
        if (!(pivot > 1e-300) || !std::isfinite(pivot)) {
            pivot = 0.0; // the inverse pivot of a dropped row: x = 0 there
            if constexpr (WithRhs) rhs[i] = 0.0;
            for (std::size_t d = 1; d < width; ++d)
                band[i * width + d] = 0.0;
            ++dropped;
            continue;
        }
        const double inverse = 1.0 / pivot;
        pivot = inverse;
        for (std::size_t d = 1; d < width && i + d < m; ++d) {
            const double factor = band[i * width + d] * inverse;
            if (factor == 0.0) continue;
            for (std::size_t e = d; e < width && i + e < m; ++e)
                band[(i + d) * width + (e - d)] -= factor * band[i * width + e];
            if constexpr (WithRhs) rhs[i + d] -= factor * rhs[i];
        }
    }
    return dropped;
}

/// Factors a symmetric positive semi-definite m × m matrix A stored as its upper band,
/// row-major: band[i · width + d] = A(i, i + d) for d < width (d = 0: the diagonal). LDLᵀ
/// without pivoting, in place: the diagonal becomes the inverses of the pivots (so that each row
/// of a solve costs one division less), the rest Dᵀ Lᵀ's band. A pivot that vanishes (≤ 1e-300
/// or not finite: a row dependent on the ones before) drops its row: x = 0 there. Returns the
/// number of rows dropped. O(m · width²).
inline std::size_t factorBandedLdlt(double* band, std::size_t m, std::size_t width)
{
    return eliminateBandedLdlt<false>(band, nullptr, m, width);
}

/// The back substitution of a factored band on an eliminated right-hand side. Only the term of
/// x[i + 1] waits for the row just solved: the others are summed first (two partial sums), so a
/// row's latency is one multiply-add and one multiply, not a chain of width − 1 multiply-adds.
inline void backSubstituteBandedLdlt(const double* band, double* rhs, std::size_t m,
                                     std::size_t width)
{
    for (std::size_t i = m; i-- > 0;) {
        const std::size_t last = std::min(width, m - i); // terms d = 1 … last − 1
        const double* row = band + i * width;
        double even = 0.0, odd = 0.0;
        std::size_t d = 2;
        for (; d + 1 < last; d += 2) {
            even += row[d] * rhs[i + d];
            odd += row[d + 1] * rhs[i + d + 1];
        }
        if (d < last) even += row[d] * rhs[i + d];
        double x = rhs[i] - (even + odd);
        if (last > 1) x -= row[1] * rhs[i + 1];
        const double inverse = row[0];
        rhs[i] = inverse != 0.0 ? x * inverse : 0.0; // 0: a dropped row
    }
}

/// Solves A x = b in place (`rhs`: b, then x) with the factor of factorBandedLdlt. O(m · width).
inline void solveFactoredBandedLdlt(const double* band, double* rhs, std::size_t m,
                                    std::size_t width)
{
    for (std::size_t i = 0; i < m; ++i) {
        const double inverse = band[i * width];
        if (inverse == 0.0) { // a dropped row
            rhs[i] = 0.0;
            continue;
        }
        const double r = rhs[i];
        if (r == 0.0) continue;
        for (std::size_t d = 1; d < width && i + d < m; ++d)
            rhs[i + d] -= band[i * width + d] * inverse * r;
    }
    backSubstituteBandedLdlt(band, rhs, m, width);
}

/// Solves A x = b in place for A as factorBandedLdlt takes it (`band` is overwritten by the
/// factor, `rhs` by x), b eliminated in the same pass as the factoring: one pass over the band
/// fewer than factorBandedLdlt and solveFactoredBandedLdlt in turn, for the chain projection's
/// single right-hand side (its gravity steps are 8 % slower with two). Returns the number of
/// rows dropped.
inline std::size_t solveBandedLdlt(double* band, double* rhs, std::size_t m, std::size_t width)
{
    const std::size_t dropped = eliminateBandedLdlt<true>(band, rhs, m, width);
    backSubstituteBandedLdlt(band, rhs, m, width);
    return dropped;
}

} // namespace chaintube::detail
