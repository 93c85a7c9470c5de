// animorder — triangle reordering for animated meshes: the manual of the algorithm layer.
//
// Plain functions over plain arrays, in the spirit of meshoptimizer. Destination first, then
// inputs; counts are size_t; strides are in bytes; no hidden state. Nothing here reads or writes
// files. Definitions (ACMR, patches, keyframes, framing, ...) follow docs/DESIGN.md exactly; each
// function names the paper section it implements.
//
// Orders are *face permutations* (DirectXMesh style): order[i] is the input triangle drawn
// i-th. A permutation never changes a triangle's corners or their winding; apply it with
// apply_triangle_order(). Empty input is a no-op. Invalid input (an index >= vertex_count, an
// index count that is not a multiple of 3, a bad permutation) throws animorder::InvalidInput,
// in Release builds too.
//
// This header declares nothing itself: each header below declares what the source of the same
// name (src/mesh/, src/overdraw/, src/algorithms/) defines. Read them in this order.
#pragma once

// The mesh every method works on: one index buffer, primitives, clips, keyframes.
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"

// Single-buffer building blocks: Sander, Nehab & Barczak 2007.
#include "animorder/patches.h"            // §4: fast linear clustering into patches (λ)
#include "animorder/static_sander07.h"    // §5: one view-independent order (equation 4)
#include "animorder/tipsify.h"            // §3: vertex-cache order in linear time
#include "animorder/triangle_matching.h"  // triangles of one index buffer found in another
#include "animorder/triangle_order.h"     // validation, applying and composing face permutations
#include "animorder/vertex_cache.h"       // ACMR / ATVR of a FIFO cache

// Animation and measurement: DESIGN.md's framing, camera, viewpoints and rasterisation rules.
// First the keyframes and the views of them ...
#include "animorder/camera.h"      // the node camera
#include "animorder/skinning.h"    // linear blend skinning of the keyframes
#include "animorder/viewpoints.h"  // icosphere / random viewpoints, framing of keyframes

// ... then the overdraw engine: one node rasterised, its fragments kept, many nodes scored.
#include "animorder/facing_filter.h"   // back faces left out before rasterising, exactly
#include "animorder/kept_fragments.h"  // a node's fragments kept compactly for orders of whole units
#include "animorder/overdraw.h"        // many orders scored at many nodes
#include "animorder/rasterizer.h"      // one node rasterised, its fragments kept per pixel

// Han & Sander 2017: k buffers chosen per (keyframe, view) by a lookup table.
#include "animorder/clustering.h"       // Algorithm 1: k-means over nodes
#include "animorder/mesh_patches.h"     // a character's patches, per primitive
#include "animorder/selection_table.h"  // the runtime lookup table

// Nehab, Barczak & Sander 2006: one order from a measured overdraw graph.
#include "animorder/nehab06.h"          // §4–5: overdraw graph, feedback arc set
#include "animorder/planar_clusters.h"  // §3: planar clusters by normals

// Beyond the papers: k-means cluster orders from measured overdraw, blended primitives.
#include "animorder/blend_orders.h"    // blended primitives back to front per cluster (issue 18)
#include "animorder/measured_order.h"  // a cluster's patches by the overdraw graph of its nodes

// The users' baseline: meshoptimizer's vertex cache and overdraw optimisers.
#include "animorder/meshopt_order.h"

// Loop subdivision of an animated mesh as one linear operator (Table 1's Δ1, Δ2 levels).
#include "animorder/loop_subdivision.h"
