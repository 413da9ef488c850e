#pragma once
// Chordal initialisation (rotation first; Martinec & Pajdla 2007, Carlone et al. ICRA 2015):
// a starting point for the non-linear solver near the global optimum, from two sparse linear
// least-squares problems, whatever the quality of the given poses.
//
//  1. Rotations: minimise sum kappa_ij |R_j - R_i R_ij|_F^2 over unconstrained 3x3 (2x2 in
//     the plane) matrices with the fixed vertices held, then project each onto SO(3) (SO(2)).
//     kappa_ij is the mean rotational information of the edge. In SE(3) the problem splits
//     into three with one matrix: one factorisation, three right-hand sides.
//  2. Positions: with those rotations the translation of every edge is linear in the
//     positions; minimise sum w_ij |t_j - t_i - R_i t_ij|^2 with w_ij the mean translational
//     information (the exact problem when it is isotropic). The matrix is the weighted graph
//     Laplacian, shared by the coordinates: one small factorisation, two or three right-hand
//     sides. The optimiser corrects the anisotropic part.

#include <vector>

#include "slam/posegraph/pose_graph.h"

namespace kestrel::slam {

/// Replaces the free poses of `graph` by the chordal estimate. `vertex_order` is a
/// fill-reducing order of all vertices (order_blocks() over the graph's edges), or empty to
/// compute one. Returns false (and leaves the graph as it was) when a linear system is
/// singular, e.g. a vertex without rotational constraint or a part of the graph not connected
/// to a fixed vertex.
bool chordal_initialize(PoseGraph2d& graph, const std::vector<int>& vertex_order = {});
bool chordal_initialize(PoseGraph3d& graph, const std::vector<int>& vertex_order = {});

}  // namespace kestrel::slam
