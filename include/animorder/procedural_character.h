// animorder — the bundled default input, made in code (procedural_character.cpp): no file needed.
#pragma once

#include "animorder/animated_mesh.h"

namespace animorder {

// The name every report gives the bundled character.
constexpr const char* kProceduralCharacterName = "procedural-character (bundled)";

// A skinned humanoid-like character of about 10k triangles with limbs that occlude one another
// (torso, head, two arms, two legs, a cape, a shield), and two clips with different motion
// ("walk", "wave"), sampled at 30 keyframes per second. Deterministic.
AnimatedMesh make_procedural_character();

}  // namespace animorder
