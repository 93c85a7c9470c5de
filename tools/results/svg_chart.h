// A small SVG chart writer for docs/RESULTS.md: line charts (several series, markers, dashed
// reference lines) and grouped bar charts, with axes, ticks, labels, a title and a legend.
//
// Byte-deterministic: every number is written with a fixed number of decimals ("%.1f" for
// coordinates, the tick step's decimals for tick labels, 3 for values in tooltips), nothing
// depends on the locale, the time or the machine. Every marker and bar carries a <title> with its
// series name and values, so a reader hovering the chart (and a test reading the file) sees the
// numbers. Sized for 640×400 by default.
#pragma once

#include <string>
#include <vector>

namespace animorder::results {

// One line of a line chart: points (x[i], y[i]); a NaN y leaves the point out.
struct LineSeries {
    std::string name;
    std::vector<double> x, y;
    bool dashed = false;  // a reference line (e.g. a method without the swept parameter)
    bool markers = true;  // one marker per point
};

struct LineChart {
    std::string title, x_label, y_label;
    std::vector<LineSeries> series;
    bool log_x = false;           // logarithmic x axis (every x must be > 0)
    std::vector<double> x_ticks;  // explicit x ticks (labelled with x_tick_decimals); empty: automatic
    int x_tick_decimals = 0;
    double min_y_span = 0;  // the y axis spans at least this much (keeps noise from looking like a trend)
    int width = 640, height = 400;
};

// One series of a grouped bar chart: values[c] is its bar in category c; NaN: no bar.
struct BarSeries {
    std::string name;
    std::vector<double> values;
};

struct BarChart {
    std::string title, x_label, y_label;
    std::vector<std::string> categories;
    std::vector<BarSeries> series;
    double baseline = 0.0;  // where the bars start (1 for overdraw ratios); the axis starts here
    int width = 640, height = 400;
};

// The SVG documents, starting with "<svg". Throw std::invalid_argument for charts that cannot be
// drawn (no series, mismatched lengths, non-positive x on a log axis, a size below 200×150).
std::string render_line_chart(const LineChart& chart);
std::string render_bar_chart(const BarChart& chart);

// printf("%.*f") with "-0.000" written as "0.000": the fixed formatting every output shares.
std::string format_fixed(double value, int decimals);

}  // namespace animorder::results
