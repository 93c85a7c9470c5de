// What the sections of RESULTS.md say about any one report (report_text.cpp): its methods in the
// canonical order, labels that tell its rows apart, the row of a method at a λ, the protocol
// sentence from its own settings, and the compact table of every row.
#pragma once

#include <string>
#include <vector>

#include "report_reader.h"

namespace animorder::results {

// The rows of `r` in the canonical method order (original, static-sander07, ..., oracle; unknown
// names last), the report's order kept within a method.
std::vector<const Method*> methods_in_order(const Report& r);

// Method names in the canonical order, then unknown names in order of appearance.
std::vector<std::string> method_names(const std::vector<const Report*>& reports);

// Whether the methods of a report use more than one k or more than one views count.
struct Varies {
    bool clusters = false, views = false;
};
Varies varies(const Report& r);

// "single λ=0.85 k=5": the name, λ when asked, k and views when the report varies them.
std::string method_label(const Method& m, const Varies& v, bool with_lambda);

// The entry of `name` at λ (any λ for methods without one); k = 5 and 162 views preferred.
const Method* find_method(const Report& r, const std::string& name, double lambda);
// The same, falling back to the entry without λ.
const Method* find_method_any(const Report& r, const std::string& name, double lambda);

std::string keyframes_total(const Report& r);              // all clips' keyframes
std::string clip_list(const Report& r);                    // "Idle (60), Walk (24)"
std::string joined(const std::vector<long long>& v);       // "5, 7"
std::string lambdas_joined(const std::vector<double>& v);  // "0.85, 3"

// One sentence of a report's protocol, from its own settings.
std::string protocol(const Report& r);

// The compact table: a row per method entry, in the report's order.
std::string compact_table(const Report& r);

}  // namespace animorder::results
