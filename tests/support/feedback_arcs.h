// Test helpers over weighted graphs (feedback_arc_set.h) with arcs in a vector.
#pragma once

#include "animorder/feedback_arc_set.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder::test {

inline std::vector<uint32_t> fas(size_t nodes, const std::vector<Arc>& arcs) {
    return order_feedback_arc_set(nodes, arcs.data(), arcs.size());
}

inline FeedbackArcs feedback(const std::vector<uint32_t>& order, const std::vector<Arc>& arcs) {
    return count_feedback_arcs(order.data(), order.size(), arcs.data(), arcs.size());
}

}  // namespace animorder::test
