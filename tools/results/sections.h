// The sections of docs/RESULTS.md, one function each, in the document's order. Each reads the
// checked inputs (report_reader.h) and returns its Markdown body; the charts a section draws go
// into Charts, to be written under OUT_DIR/results/. Which file writes which section:
//   section_settings.cpp     settings      every report's input and settings
//   section_table1.cpp       table1        ganfaul-idle{,-sub1,-sub2}.json (+ ganfaul-clips.json) against Table 1
//   section_characters.cpp   characters    characters/*.json
//   section_sweeps.cpp       views, lambda, clusters   sweep-views.json, sweep-lambda.json, sweep-k.json (Figs. 3, 6, 7)
//   section_clips.cpp        clips         ganfaul-clips.json (Figs. 8 and 5)
//   section_measured.cpp     measured      measured/*.json: measured cluster orders (issue 15) against single
//   section_benchmarks.cpp   render-time, nehab06, performance, other   render-time.json, the reports'
//                            static-nehab06, notes-performance.md, *.txt
//   section_materials.cpp    materials     materials/*.json: double-sided OVR, blend error (issue 18)
#pragma once

#include <map>
#include <string>

#include "report_reader.h"
#include "svg_chart.h"

namespace animorder::results {

struct Section {
    std::string id, title, body;  // id: the <id> of notes-<id>.md appended to it
};

// The charts of one run, by file name in results/.
class Charts {
public:
    // The chart's Markdown reference; a chart with nothing to draw (e.g. reports without per-clip
    // values) gives a line saying so instead of failing the whole document.
    std::string chart(const std::string& file, const LineChart& chart, const std::string& alt);
    std::string chart(const std::string& file, const BarChart& chart, const std::string& alt);
    const std::map<std::string, std::string>& svgs() const { return svgs_; }

private:
    template <class Chart>
    std::string draw(const std::string& file, const Chart& chart, const std::string& alt,
                     std::string (*render)(const Chart&));
    std::map<std::string, std::string> svgs_;
};

// The report `file`, or null with "not run: FILE missing" appended to `body`.
const Report* report_or_not_run(const Inputs& in, const std::string& file, std::string& body);

Section settings_section(const Inputs& in);
Section table1_section(const Inputs& in);
Section characters_section(const Inputs& in, Charts& charts);
Section views_section(const Inputs& in, Charts& charts);
Section lambda_section(const Inputs& in, Charts& charts);
Section clusters_section(const Inputs& in, Charts& charts);
Section clips_section(const Inputs& in, Charts& charts);
Section measured_section(const Inputs& in, Charts& charts);
Section render_time_section(const Inputs& in);
Section nehab06_section(const Inputs& in);
Section performance_section(const Inputs& in);  // its figures: notes-performance.md (templates.h)
Section other_section(const Inputs& in);        // empty body when there is no other *.txt
Section materials_section(const Inputs& in);     // materials/*.json (issue 18)

}  // namespace animorder::results
