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
// name (src/mesh/, src/algorithms/) defines. Read them in this order.
#pragma once

// The mesh every method works on: one index buffer, primitives, clips, keyframes.
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"

// Single-buffer building blocks: Sander, Nehab & Barczak 2007.
#include "animorder/patches.h"          // §4: fast linear clustering into patches (λ)
#include "animorder/static_sander07.h"  // §5: one view-independent order (equation 4)
#include "animorder/tipsify.h"          // §3: vertex-cache order in linear time
#include "animorder/triangle_order.h"   // validation, applying and composing face permutations
#include "animorder/vertex_cache.h"     // ACMR / ATVR of a FIFO cache

// Animation and measurement: DESIGN.md's framing, camera, viewpoints and rasterisation rules.
#include "animorder/camera.h"      // the node camera
#include "animorder/overdraw.h"    // many orders scored at many nodes
#include "animorder/rasterizer.h"  // one node rasterised, its fragments kept per pixel
#include "animorder/skinning.h"    // linear blend skinning of the keyframes
#include "animorder/viewpoints.h"  // icosphere / random viewpoints, framing of keyframes

// Han & Sander 2017: k buffers chosen per (keyframe, view) by a lookup table.
#include "animorder/clustering.h"       // Algorithm 1: k-means over nodes
#include "animorder/mesh_patches.h"     // a character's patches, per primitive
#include "animorder/selection_table.h"  // the runtime lookup table

// Nehab, Barczak & Sander 2006: one order from a measured overdraw graph.
#include "animorder/nehab06.h"          // §4–5: overdraw graph, feedback arc set
#include "animorder/planar_clusters.h"  // §3: planar clusters by normals

// The users' baseline: meshoptimizer's vertex cache and overdraw optimisers.
#include "animorder/meshopt_order.h"

// Loop subdivision of an animated mesh as one linear operator (Table 1's Δ1, Δ2 levels).
#include "animorder/loop_subdivision.h"
