// RESULTS.md's "Every skinned character": from characters/*.json, a summary table and bar chart
// (characters-ovr.svg) of mean OVR per character and method at λ = 0.85, then each character's
// protocol and compact table.
#include <filesystem>

#include "markdown.h"
#include "report_text.h"
#include "sections.h"

namespace animorder::results {

namespace fs = std::filesystem;

Section characters_section(const Inputs& in, Charts& charts) {
    Section s{"characters", "Every skinned character", ""};
    std::string& b = s.body;
    if (in.characters.empty()) {
        b += not_run("characters/*.json");
        return s;
    }
    std::vector<const Report*> reports;
    for (const std::string& name : in.characters) reports.push_back(in.get(name));
    const std::vector<std::string> names = method_names(reports);
    b += "One `animorder evaluate` run per skinned character of `../shared/data`, every clip; each character's "
         "protocol is stated with its table. Summary: mean OVR at λ = 0.85 (methods without λ: their only row; "
         "single and joint at k = 5 and 162 views where the report has several).\n\n";
    std::vector<std::string> header = {"character", "triangles", "clips", "keyframes"};
    header.insert(header.end(), names.begin(), names.end());
    std::vector<std::vector<std::string>> rows;
    BarChart chart;
    chart.title = "Overdraw per character (λ = 0.85)";
    chart.x_label = "character";
    chart.y_label = "OVR (mean)";
    chart.baseline = 1.0;
    for (const std::string& n : names) chart.series.push_back({n, {}});
    for (size_t i = 0; i < reports.size(); ++i) {
        const Report& r = *reports[i];
        const std::string character = fs::path(in.characters[i]).stem().string();
        chart.categories.push_back(character);
        std::vector<std::string> cells = {character, count(r.triangles), std::to_string(r.clips.size()),
                                          keyframes_total(r)};
        for (size_t k = 0; k < names.size(); ++k) {
            const Method* m = find_method_any(r, names[k], 0.85);
            cells.push_back(m ? f3(m->ovr_mean) : kDash);
            chart.series[k].values.push_back(m ? m->ovr_mean : kNaN);
        }
        rows.push_back(cells);
    }
    b += table(header, rows) + "\n";
    b += charts.chart("characters-ovr.svg", chart, "Mean OVR per character and method at lambda 0.85") + "\n";
    for (size_t i = 0; i < reports.size(); ++i) {
        const Report& r = *reports[i];
        b += "### " + fs::path(in.characters[i]).stem().string() + "\n\n";
        b += protocol(r) + " Clips: " + clip_list(r) + ".\n\n" + compact_table(r) + "\n";
    }
    return s;
}

}  // namespace animorder::results
