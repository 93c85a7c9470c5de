// Private to src/overdraw: the attribute that inlines a helper into each caller, so that every
// copy of a per-node loop (portable, AVX2, AVX-512) compiles the helper for its own instructions.
#pragma once

#define ANIMORDER_ALWAYS_INLINE inline __attribute__((always_inline))
