// ChainTube formats — which collider a hose does not collide with: one rule for the runtime, the
// export round trip, the clearance check and the editor. Header only: the runtime uses it
// without linking chaintube_formats (it reaches this folder through chaintube_paths).
//
// The rule: a hose's end sits in the node it is attached to by design, and that node sits in the
// parts above it (an attachment on "/rig/valve/inlet" is inside "/rig/valve" too). So a scene
// node that is an attachment node of the hose, or an ancestor of one, is exempt for that hose.
// Children and siblings of the attachment node are not exempt; an attachment fixed to the world
// (no node) exempts nothing.
#pragma once

#include <string_view>

namespace chaintube::formats {

/// True if `candidate` is `attached` or one of its ancestors, i.e. a hose attached to node
/// `attached` neither collides with nor is checked for clearance against `candidate`.
/// `parentOf(n)` returns the parent index of node n, a negative value at a root; the hierarchy
/// must have no cycle. Negative `attached` (fixed to the world) or `candidate` give false.
template <class ParentOf>
bool attachmentExempts(int attached, int candidate, const ParentOf& parentOf)
{
    if (candidate < 0) return false;
    for (int n = attached; n >= 0; n = parentOf(n))
        if (n == candidate) return true;
    return false;
}

/// The same rule on node paths ("/rig/valve/inlet"): `candidate` equals `attached` or is a
/// path prefix of it ending at a '/' ("/rig/valve" is, "/rig/val" and "/rig/valveX" are not).
/// An empty path gives false.
inline bool attachmentExemptsPath(std::string_view attached, std::string_view candidate)
{
    if (attached.empty() || candidate.empty()) return false;
    if (attached == candidate) return true;
    return attached.size() > candidate.size() &&
           attached.substr(0, candidate.size()) == candidate && attached[candidate.size()] == '/';
}

} // namespace chaintube::formats
