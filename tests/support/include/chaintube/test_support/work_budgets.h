// The Newton-step budgets lib/README.md states ("Budgets a call") for a hose fixed at both ends
// whose middle is grabbed: the bounds the real-time walks of tests/lib and the real-time
// benchmark check every frame against. Header-only, no dependencies.
#pragma once

namespace chaintube::test_support {

/// A grab between two fixed points: 12 to bow a straight span, 4 steps of at most 6 hard and
/// 6 soft Newton steps to advance, 12 to solve the span again with the point soft.
inline constexpr int kGrabBudget = 12 + 4 * (6 + 6) + 12;

/// The same with a clip between one fixed end and the grabbed point (lib/README.md, "Clips"):
/// two spans (end to clip, clip to end through the grabbed point). At most three slide attempts,
/// each closing both spans (32 Newton steps a span), then the grab: 12 a span to bow,
/// 4 × (6 + 6) to advance the grabbed point's span and 12 to solve the other, 12 a span for the
/// fallback with the point soft.
inline constexpr int kClipGrabBudget = 3 * (2 * 32) + (2 * 12 + 4 * (6 + 6) + 12 + 2 * 12);

/// Contacts resolved after a grab or a step (Hose::applyCollisions): 8 steps of the chain
/// projection with the contacts and the closing of both spans (32 a span).
inline constexpr int kContactBudget = 8 + 2 * 32;

/// A grab of a hose with colliders: the grab, again from the previous shape when a collider
/// stopped the grabbed point, and the contacts.
inline constexpr int kContactGrabBudget = 2 * kGrabBudget + kContactBudget;

/// One gravity step (Hose::step) of a hose whose held point splits it into two spans: four
/// attempts of 8 projection steps and the closing of both spans (32 a span).
inline constexpr int kStepBudget = 4 * (8 + 2 * 32);

} // namespace chaintube::test_support
