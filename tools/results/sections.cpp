// What the sections of RESULTS.md share (sections.h): the charts of a run, and the "not run" line
// of a missing report.
#include "sections.h"

#include <stdexcept>

#include "markdown.h"

namespace animorder::results {

template <class Chart>
std::string Charts::draw(const std::string& file, const Chart& chart, const std::string& alt,
                         std::string (*render)(const Chart&)) {
    try {
        svgs_[file] = render(chart);
    } catch (const std::invalid_argument& e) {
        return std::string("(chart ") + file + " not drawn: " + e.what() + ")\n";
    }
    return "![" + alt + "](results/" + file + ")\n";
}

std::string Charts::chart(const std::string& file, const LineChart& chart, const std::string& alt) {
    return draw(file, chart, alt, render_line_chart);
}

std::string Charts::chart(const std::string& file, const BarChart& chart, const std::string& alt) {
    return draw(file, chart, alt, render_bar_chart);
}

const Report* report_or_not_run(const Inputs& in, const std::string& file, std::string& body) {
    const Report* r = in.get(file);
    if (!r) body += not_run(file);
    return r;
}

}  // namespace animorder::results
