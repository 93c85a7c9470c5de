// RESULTS.md's "Inputs and settings": a row per evaluation report read (ganfaul-idle{,-sub1,-sub2},
// ganfaul-clips, the sweeps, then characters/*.json) with the input and the settings it records.
#include "markdown.h"
#include "report_text.h"
#include "sections.h"

namespace animorder::results {

Section settings_section(const Inputs& in) {
    Section s{"settings", "Inputs and settings", ""};
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> order = {"ganfaul-idle.json",  "ganfaul-idle-sub1.json", "ganfaul-idle-sub2.json",
                                      "ganfaul-clips.json", "sweep-views.json",       "sweep-lambda.json",
                                      "sweep-k.json"};
    order.insert(order.end(), in.characters.begin(), in.characters.end());
    for (const std::string& name : order) {
        const Report* found = in.get(name);
        if (!found) continue;
        const Report& r = *found;
        const std::string eval =
            count(r.eval_views) + " × " + count(r.eval_resolution) + "², seed " + count(r.eval_seed);
        const std::string clustering = (r.views.empty() ? std::string(kDash) : joined(r.views)) + " views × " +
                                       count(r.resolution) + "², seed " + count(r.seed);
        rows.push_back({"`" + name + "`", "`" + r.input + "`", count(r.triangles),
                        std::to_string(r.clips.size()) + " (" + keyframes_total(r) + ")", eval, clustering,
                        r.lambdas.empty() ? kDash : lambdas_joined(r.lambdas), count(r.threads), f1(r.t_total / 60.0)});
    }
    if (rows.empty()) {
        s.body = "No evaluation reports were found.\n";
        return s;
    }
    s.body =
        "Every report read, with the settings it records (evaluation: random views per keyframe × resolution, "
        "seed; clustering: icosphere viewpoints × resolution, k-means seed). OVR is the mean of per-node ratios "
        "unless a column says pooled (Σ passed / Σ visible); ACMR and ATVR are for a FIFO vertex cache of 16 "
        "entries unless a report says otherwise.\n\n" +
        table({"report", "input", "triangles", "clips (keyframes)", "evaluation", "clustering", "λ", "threads",
               "run time min"},
              rows, 9);
    return s;
}

}  // namespace animorder::results
