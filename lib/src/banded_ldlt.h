// The banded symmetric solve of the chain projection (projection.cpp: gravity steps, contacts,
// bends giving way; solved from both ends at once, and again from the rows a change of its
// working set reaches), of the span solver's small dense normal equations (span_solver.cpp: a
// band as wide as the matrix) and of its steps towards a held target (a block-tridiagonal band
// factored once and solved for several right-hand sides).
// Internal to lib/.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace chaintube::detail {

/// One row of the downward LDLᵀ elimination: row i's pivot replaced by its inverse, the rows
/// below it (up to, not including, row `limit`) updated, `rhs` too when WithRhs. A vanishing
/// pivot (≤ 1e-300 or not finite) drops the row: its inverse pivot, right-hand side and
/// couplings within the limit become 0. Returns whether it was dropped.
template <bool WithRhs>
[[gnu::always_inline]] inline bool eliminateRowDown(double* band, double* rhs, std::size_t i,
                                                    std::size_t limit, std::size_t width)
{
    double& pivot = band[i * width];
    if (!(pivot > 1e-300) || !std::isfinite(pivot)) {
        pivot = 0.0; // the inverse pivot of a dropped row: x = 0 there
        if constexpr (WithRhs) rhs[i] = 0.0;
        for (std::size_t d = 1; d < width && i + d < limit; ++d)
            band[i * width + d] = 0.0;
        return true;
    }
    const double inverse = 1.0 / pivot;
    pivot = inverse;
    for (std::size_t d = 1; d < width && i + d < limit; ++d) {
        const double factor = band[i * width + d] * inverse;
        if (factor == 0.0) continue;
        for (std::size_t e = d; e < width && i + e < limit; ++e)
            band[(i + d) * width + (e - d)] -= factor * band[i * width + e];
        if constexpr (WithRhs) rhs[i + d] -= factor * rhs[i];
    }
    return false;
}

/// The LDLᵀ elimination of factorBandedLdlt, with `rhs` (b) eliminated in the same pass when
/// WithRhs (solveBandedLdlt's one pass over the band).
template <bool WithRhs>
[[gnu::always_inline]] inline std::size_t eliminateBandedLdlt(double* band, double* rhs,
                                                              std::size_t m, std::size_t width)
{
    std::size_t dropped = 0;
    for (std::size_t i = 0; i < m; ++i)
        dropped += eliminateRowDown<WithRhs>(band, rhs, i, m, width);
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

/// One row of the back substitution of a downward factor: x_i from the rows after it, up to (not
/// including) row `limit`. Only the term of x[i + 1] waits for the row just solved: the others
/// are summed first (two partial sums), so a row's latency is one multiply-add and one
/// multiply, not a chain of width − 1 multiply-adds.
[[gnu::always_inline]] inline void backSubstituteRowDown(const double* band, double* rhs,
                                                         std::size_t i, std::size_t limit,
                                                         std::size_t width)
{
    const std::size_t last = std::min(width, limit - i); // terms d = 1 … last − 1
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

/// The back substitution of a factored band on an eliminated right-hand side.
[[gnu::always_inline]] inline void backSubstituteBandedLdlt(const double* band, double* rhs,
                                                            std::size_t m, std::size_t width)
{
    for (std::size_t i = m; i-- > 0;)
        backSubstituteRowDown(band, rhs, i, m, width);
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
[[gnu::always_inline]] inline std::size_t solveBandedLdlt(double* band, double* rhs, std::size_t m,
                                                          std::size_t width)
{
    const std::size_t dropped = eliminateBandedLdlt<true>(band, rhs, m, width);
    backSubstituteBandedLdlt(band, rhs, m, width);
    return dropped;
}

/// solveBandedLdlt of a small dense matrix (width = m, the span solver's normal equations),
/// with m a constant for its usual sizes so the loops unroll (the same arithmetic in the same
/// order).
inline std::size_t solveDenseLdlt(double* band, double* rhs, std::size_t m)
{
    switch (m) {
    case 4:
        return solveBandedLdlt(band, rhs, 4, 4);
    case 7:
        return solveBandedLdlt(band, rhs, 7, 7);
    default:
        return solveBandedLdlt(band, rhs, m, m);
    }
}

/// One row of the upward elimination (the mirror of eliminateRowDown, A = U D Uᵀ from the last
/// row): row i's pivot replaced by its inverse, the rows above it updated with its column
/// (stored in their bands), and the right-hand side. Every row above it that it couples with
/// must exist (i ≥ width − 1). A vanishing pivot drops the row. Returns whether it was dropped.
[[gnu::always_inline]] inline bool eliminateRowUp(double* band, double* rhs, std::size_t i,
                                                  std::size_t width)
{
    double& pivot = band[i * width];
    if (!(pivot > 1e-300) || !std::isfinite(pivot)) {
        pivot = 0.0;
        rhs[i] = 0.0;
        for (std::size_t d = 1; d < width; ++d)
            band[(i - d) * width + d] = 0.0;
        return true;
    }
    const double inverse = 1.0 / pivot;
    pivot = inverse;
    for (std::size_t d1 = 1; d1 < width; ++d1) {
        const double factor = band[(i - d1) * width + d1] * inverse;
        if (factor == 0.0) continue;
        for (std::size_t d2 = d1; d2 < width; ++d2)
            band[(i - d2) * width + (d2 - d1)] -= factor * band[(i - d2) * width + d2];
        rhs[i - d1] -= factor * rhs[i];
    }
    return false;
}

/// One row of the back substitution of an upward factor: x_i from the rows before it (as
/// backSubstituteRowDown, two partial sums).
[[gnu::always_inline]] inline void backSubstituteRowUp(const double* band, double* rhs,
                                                       std::size_t i, std::size_t width)
{
    double even = 0.0, odd = 0.0;
    std::size_t d = 2;
    for (; d + 1 < width; d += 2) {
        even += band[(i - d) * width + d] * rhs[i - d];
        odd += band[(i - d - 1) * width + d + 1] * rhs[i - d - 1];
    }
    if (d < width) even += band[(i - d) * width + d] * rhs[i - d];
    double x = rhs[i] - (even + odd);
    if (width > 1) x -= band[(i - 1) * width + 1] * rhs[i - 1];
    const double inverse = band[i * width];
    rhs[i] = inverse != 0.0 ? x * inverse : 0.0;
}

/// The end of a twisted solve, once both halves are eliminated: the separator [top, bottom)
/// eliminated (its rows' couplings with each other only; those with the halves are the halves'
/// factors) and substituted back, then the two halves substituted back outwards, a row of each
/// in turn. Returns the number of separator rows dropped.
[[gnu::always_inline]] inline std::size_t
solveTwistedSeparatorAndBack(double* band, double* rhs, std::size_t m, std::size_t width,
                             std::size_t top, std::size_t bottom)
{
    std::size_t dropped = 0;
    for (std::size_t i = top; i < bottom; ++i)
        dropped += eliminateRowDown<true>(band, rhs, i, bottom, width);
    for (std::size_t i = bottom; i-- > top;)
        backSubstituteRowDown(band, rhs, i, bottom, width);
    const std::size_t topRows = top, bottomRows = m - bottom;
    const std::size_t both = std::min(topRows, bottomRows);
    for (std::size_t t = 0; t < both; ++t) {
        backSubstituteRowDown(band, rhs, top - 1 - t, m, width);
        backSubstituteRowUp(band, rhs, bottom + t, width);
    }
    for (std::size_t t = both; t < topRows; ++t)
        backSubstituteRowDown(band, rhs, top - 1 - t, m, width);
    for (std::size_t t = both; t < bottomRows; ++t)
        backSubstituteRowUp(band, rhs, bottom + t, width);
    return dropped;
}

/// solveBandedLdlt from both ends at once (a twisted factorization): the first half of the rows
/// eliminated downwards and the second half upwards, a row of each in turn, so that the two
/// chains of pivots — each row's pivot waits for the row before it — overlap in the CPU; they
/// meet in a separator of width − 1 rows in the middle, which both halves update and which is
/// solved last, then the two halves are substituted back outwards, again in turn. The same
/// system and the same work as solveBandedLdlt, a different order (so rounding differs in the
/// last bits); 1.3–1.5× faster at the chain projection's sizes (tests/bench/PERFORMANCE-NOTES.md).
/// A row whose pivot vanishes is dropped as there; of a set of dependent rows, the one that each
/// half reaches last is dropped. Fewer than 4 · width rows: solveBandedLdlt.
[[gnu::always_inline]] inline std::size_t solveBandedLdltTwistedIn(double* band, double* rhs,
                                                                   std::size_t m, std::size_t width)
{
    if (width < 2 || m < 4 * width) return solveBandedLdlt(band, rhs, m, width);
    const std::size_t q = width - 1; // half-bandwidth
    const std::size_t top = (m - q) / 2,
                      bottom = top + q; // [0, top) ↓, [top, bottom), [bottom, m) ↑
    const std::size_t topRows = top, bottomRows = m - bottom;
    const std::size_t both = std::min(topRows, bottomRows);
    std::size_t dropped = 0;
    for (std::size_t t = 0; t < both; ++t) {
        dropped += eliminateRowDown<true>(band, rhs, t, m, width);
        dropped += eliminateRowUp(band, rhs, m - 1 - t, width);
    }
    for (std::size_t t = both; t < topRows; ++t)
        dropped += eliminateRowDown<true>(band, rhs, t, m, width);
    for (std::size_t t = both; t < bottomRows; ++t)
        dropped += eliminateRowUp(band, rhs, m - 1 - t, width);
    return dropped + solveTwistedSeparatorAndBack(band, rhs, m, width, top, bottom);
}

/// solveBandedLdltTwistedIn with the band's width a constant for the chain projection's usual
/// widths (lengths alone: 2; with bends: 5; with contacts too: 7), so the rows' loops unroll (the
/// same arithmetic in the same order).
inline std::size_t solveBandedLdltTwisted(double* band, double* rhs, std::size_t m,
                                          std::size_t width)
{
    switch (width) {
    case 2:
        return solveBandedLdltTwistedIn(band, rhs, m, 2);
    case 5:
        return solveBandedLdltTwistedIn(band, rhs, m, 5);
    case 7:
        return solveBandedLdltTwistedIn(band, rhs, m, 7);
    default:
        return solveBandedLdltTwistedIn(band, rhs, m, width);
    }
}

/// eliminateRowDown<true> of a row whose elimination is already in `band` (its factor: the
/// inverse pivot and its couplings), for rows below it that are being factored again: the
/// updates it makes to the rows from `from` on, and to every row's right-hand side, in the
/// same arithmetic. Returns whether the row was dropped.
[[gnu::always_inline]] inline bool replayRowDown(double* band, double* rhs, std::size_t i,
                                                 std::size_t from, std::size_t limit,
                                                 std::size_t width)
{
    const double inverse = band[i * width];
    if (inverse == 0.0) { // dropped: its couplings are 0
        rhs[i] = 0.0;
        return true;
    }
    for (std::size_t d = 1; d < width && i + d < limit; ++d) {
        const double factor = band[i * width + d] * inverse;
        if (factor == 0.0) continue;
        if (i + d >= from)
            for (std::size_t e = d; e < width && i + e < limit; ++e)
                band[(i + d) * width + (e - d)] -= factor * band[i * width + e];
        rhs[i + d] -= factor * rhs[i];
    }
    return false;
}

/// eliminateRowUp's mirror of replayRowDown: the updates of an eliminated row i to the entries
/// A(k′, k) with k ≤ `to` (being factored again) and to every right-hand side above it.
[[gnu::always_inline]] inline bool replayRowUp(double* band, double* rhs, std::size_t i,
                                               std::size_t to, std::size_t width)
{
    const double inverse = band[i * width];
    if (inverse == 0.0) {
        rhs[i] = 0.0;
        return true;
    }
    for (std::size_t d1 = 1; d1 < width; ++d1) {
        const double factor = band[(i - d1) * width + d1] * inverse;
        if (factor == 0.0) continue;
        if (i - d1 <= to)
            for (std::size_t d2 = d1; d2 < width; ++d2)
                band[(i - d2) * width + (d2 - d1)] -= factor * band[(i - d2) * width + d2];
        rhs[i - d1] -= factor * rhs[i];
    }
    return false;
}

/// solveBandedLdltTwistedIn again after rows and columns changedFirst … changedLast of the
/// matrix changed. The matrix is `system` (as solveBandedLdlt takes it) with the rows and columns
/// i where keep[i] is 0 decoupled (a unit diagonal, no coupling, b_i = 0: x_i = 0), b is
/// `systemRhs`; `band` holds the factor of the matrix before the change, as the last solve left
/// it. Only the rows whose elimination the change reaches are factored again (in the top half
/// from changedFirst − (width − 1) on, in the bottom half up to changedLast + width − 1, and the
/// separator); the others' updates to those rows are replayed from their factors. The same
/// arithmetic in the same order as solveBandedLdltTwisted of the new matrix: the same x and
/// factor, bit for bit. Returns the number of rows dropped.
[[gnu::always_inline]] inline std::size_t
resolveBandedLdltTwistedIn(double* band, double* rhs, std::size_t m, std::size_t width,
                           std::size_t changedFirst, std::size_t changedLast, const double* system,
                           const double* systemRhs, const unsigned char* keep)
{
    const std::size_t q = width - 1;
    const std::size_t downFrom = changedFirst > q ? changedFirst - q : 0;
    for (std::size_t i = 0; i < m; ++i)
        rhs[i] = keep[i] ? systemRhs[i] : 0.0;
    const bool twisted = width >= 2 && m >= 4 * width;
    const std::size_t top = twisted ? (m - q) / 2 : m, bottom = twisted ? top + q : m;
    // Factored again: the whole rows fullFrom … top − 1, and from the separator on the entries
    // of the columns up to upTo (the separator's own always).
    const std::size_t fullFrom = std::min(downFrom, top);
    const std::size_t upTo =
        twisted ? std::max(std::min(m - 1, changedLast + q), bottom - 1) : top - 1;
    auto restored = [&](std::size_t i, std::size_t d) __attribute__((always_inline))
    {
        return i < top ? i >= fullFrom : i + d <= upTo;
    };
    if (fullFrom < top)
        std::copy(system + fullFrom * width, system + top * width, band + fullFrom * width);
    for (std::size_t i = top; i <= upTo && i < m; ++i)
        std::copy(system + i * width, system + i * width + std::min(width, upTo + 1 - i),
                  band + i * width);
    for (std::size_t r = fullFrom; r <= upTo && r < m; ++r) {
        if (keep[r]) continue;
        for (std::size_t d = 0; d < width && restored(r, d); ++d)
            band[r * width + d] = d == 0 ? 1.0 : 0.0;
        for (std::size_t d = 1; d < width && d <= r; ++d)
            if (restored(r - d, d)) band[(r - d) * width + d] = 0.0;
    }
    std::size_t dropped = 0;
    auto down = [&](std::size_t t) __attribute__((always_inline))
    {
        return t < fullFrom ? replayRowDown(band, rhs, t, fullFrom, m, width)
                            : eliminateRowDown<true>(band, rhs, t, m, width);
    };
    if (!twisted) {
        for (std::size_t i = 0; i < m; ++i)
            dropped += down(i);
        backSubstituteBandedLdlt(band, rhs, m, width);
        return dropped;
    }
    auto up = [&](std::size_t t) __attribute__((always_inline))
    {
        const std::size_t i = m - 1 - t;
        return i > upTo ? replayRowUp(band, rhs, i, upTo, width)
                        : eliminateRowUp(band, rhs, i, width);
    };
    const std::size_t topRows = top, bottomRows = m - bottom;
    const std::size_t both = std::min(topRows, bottomRows);
    for (std::size_t t = 0; t < both; ++t) {
        dropped += down(t);
        dropped += up(t);
    }
    for (std::size_t t = both; t < topRows; ++t)
        dropped += down(t);
    for (std::size_t t = both; t < bottomRows; ++t)
        dropped += up(t);
    return dropped + solveTwistedSeparatorAndBack(band, rhs, m, width, top, bottom);
}

/// resolveBandedLdltTwistedIn with the usual widths constant (as solveBandedLdltTwisted).
inline std::size_t resolveBandedLdltTwisted(double* band, double* rhs, std::size_t m,
                                            std::size_t width, std::size_t changedFirst,
                                            std::size_t changedLast, const double* system,
                                            const double* systemRhs, const unsigned char* keep)
{
    switch (width) {
    case 2:
        return resolveBandedLdltTwistedIn(band, rhs, m, 2, changedFirst, changedLast, system,
                                          systemRhs, keep);
    case 5:
        return resolveBandedLdltTwistedIn(band, rhs, m, 5, changedFirst, changedLast, system,
                                          systemRhs, keep);
    case 7:
        return resolveBandedLdltTwistedIn(band, rhs, m, 7, changedFirst, changedLast, system,
                                          systemRhs, keep);
    default:
        return resolveBandedLdltTwistedIn(band, rhs, m, width, changedFirst, changedLast, system,
                                          systemRhs, keep);
    }
}

} // namespace chaintube::detail
