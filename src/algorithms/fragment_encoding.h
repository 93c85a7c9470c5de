// Private to src/algorithms: how NodeFragments::fragments (overdraw.h) packs one fragment into a
// uint32_t. The low 31 bits are the triangle index; the top bit is set when the fragment's depth
// equals the previous fragment's of the same pixel (fragments run nearest first), so the two are
// one depth group of which only the one drawn first can pass. rasterizer.cpp writes it;
// rasterizer.cpp and nehab06.cpp read it.
#pragma once

#include <cstdint>

namespace animorder {

constexpr uint32_t kTieBit = 0x80000000u;
constexpr uint32_t kTriangleMask = 0x7fffffffu;

}  // namespace animorder
