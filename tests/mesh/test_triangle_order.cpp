#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include <gtest/gtest.h>

#include <vector>

using namespace animorder;

TEST(ValidateIndices, AcceptsInRangeTriangleList) {
    const std::vector<uint32_t> ib{0, 1, 2, 2, 1, 3};
    EXPECT_NO_THROW(validate_indices(ib.data(), ib.size(), 4));
}

TEST(ValidateIndices, EmptyIsFine) { EXPECT_NO_THROW(validate_indices(nullptr, 0, 0)); }

TEST(ValidateIndices, OutOfRangeNamesTheIndex) {
    const std::vector<uint32_t> ib{0, 1, 2, 2, 1, 7};
    try {
        validate_indices(ib.data(), ib.size(), 4);
        FAIL() << "no error";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("index 5 (triangle 1) is 7"), std::string::npos) << e.what();
    }
}

TEST(ValidateIndices, RejectsPartialTriangle) {
    const std::vector<uint32_t> ib{0, 1, 2, 2};
    EXPECT_THROW(validate_indices(ib.data(), ib.size(), 4), InvalidInput);
}

TEST(ValidateTriangleOrder, RejectsRepeatsAndOutOfRange) {
    const std::vector<uint32_t> repeat{0, 1, 1};
    const std::vector<uint32_t> out_of_range{0, 1, 3};
    EXPECT_THROW(validate_triangle_order(repeat.data(), 3), InvalidInput);
    EXPECT_THROW(validate_triangle_order(out_of_range.data(), 3), InvalidInput);
}

TEST(ApplyTriangleOrder, MovesWholeTrianglesKeepingCornerSequence) {
    const std::vector<uint32_t> ib{0, 1, 2, 3, 4, 5, 6, 7, 8};
    const std::vector<uint32_t> order{2, 0, 1};
    std::vector<uint32_t> out(9);
    apply_triangle_order(out.data(), ib.data(), order.data(), 3);
    EXPECT_EQ(out, (std::vector<uint32_t>{6, 7, 8, 0, 1, 2, 3, 4, 5}));
}

TEST(ApplyTriangleOrder, RejectsAliasing) {
    std::vector<uint32_t> ib{0, 1, 2, 3, 4, 5};
    const std::vector<uint32_t> order{1, 0};
    EXPECT_THROW(apply_triangle_order(ib.data(), ib.data(), order.data(), 2), InvalidInput);
}

TEST(ComposeTriangleOrders, AppliesOuterToInnersOutput) {
    // inner draws triangles 3,1,0,2; outer then takes inner's positions 1,3,0,2 → triangles 1,2,3,0.
    const std::vector<uint32_t> inner{3, 1, 0, 2}, outer{1, 3, 0, 2};
    std::vector<uint32_t> out(4);
    compose_triangle_orders(out.data(), inner.data(), outer.data(), 4);
    EXPECT_EQ(out, (std::vector<uint32_t>{1, 2, 3, 0}));
}
