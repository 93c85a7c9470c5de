// The SVG chart writer of make_results (svg_chart.h): fixed layout, fixed number formatting.
#include "svg_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace animorder::results {
namespace {

// Tableau 10: distinguishable, and each series also gets its own marker shape.
const char* const kPalette[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
                                "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"};
constexpr size_t kPaletteSize = sizeof kPalette / sizeof kPalette[0];

constexpr double kCharWidth = 6.5;   // estimated advance of a 12px sans-serif character
constexpr double kLegendRow = 18.0;  // height of a legend row

std::string escape(const std::string& text) {
    std::string out;
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&apos;"; break;
            default: out += c;
        }
    }
    return out;
}

// Characters, not bytes: UTF-8 continuation bytes do not advance.
size_t text_length(const std::string& text) {
    size_t n = 0;
    for (unsigned char c : text) n += (c & 0xC0) != 0x80;
    return n;
}

double text_width(const std::string& text) { return kCharWidth * double(text_length(text)); }

std::string num(double value) { return format_fixed(value, 1); }

// Shortest of 0..6 decimals that writes `value` exactly (to 1e-9): 12, 0.85, 2.5.
std::string format_trimmed(double value) {
    for (int d = 0; d < 6; ++d) {
        const double scaled = value * std::pow(10.0, d);
        if (std::fabs(scaled - std::round(scaled)) < 1e-6 * std::max(1.0, std::fabs(scaled)))
            return format_fixed(value, d);
    }
    return format_fixed(value, 6);
}

// Decimals needed to write every multiple of `step` exactly.
int decimals_for(double step) {
    for (int d = 0; d < 6; ++d) {
        const double scaled = step * std::pow(10.0, d);
        if (std::fabs(scaled - std::round(scaled)) < 1e-6) return d;
    }
    return 6;
}

// A "nice" tick step (1, 2, 2.5 or 5 × 10^n) giving about `target` intervals over `span`.
double nice_step(double span, int target) {
    const double raw = span / target;
    const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    const double fraction = raw / magnitude;
    const double nice = fraction <= 1.0   ? 1.0
                        : fraction <= 2.0 ? 2.0
                        : fraction <= 2.5 ? 2.5
                        : fraction <= 5.0 ? 5.0
                                          : 10.0;
    return nice * magnitude;
}

struct Axis {
    double lo = 0, hi = 1;      // in axis units (log10(x) on a log axis)
    std::vector<double> ticks;  // in data units
    int decimals = 0;
    bool log = false;
    double to_unit(double v) const { return log ? std::log10(v) : v; }
};

// Linear axis covering [lo, hi], padded by 4% (`pad`) and rounded out to whole steps
// (`round_out`; otherwise the ticks are the whole steps inside the range).
Axis linear_axis(double lo, double hi, int target, bool pad, bool round_out = true) {
    if (!(hi > lo)) {
        const double d = std::fabs(lo) < 1.0 ? 0.05 : 0.05 * std::fabs(lo);
        lo -= d;
        hi += d;
    }
    if (pad) {
        const double p = 0.04 * (hi - lo);
        lo -= p;
        hi += p;
    }
    const double step = nice_step(hi - lo, target);
    Axis axis;
    axis.lo = round_out ? std::floor(lo / step + 1e-9) * step : lo;
    axis.hi = round_out ? std::ceil(hi / step - 1e-9) * step : hi;
    axis.decimals = decimals_for(step);
    for (long i = long(std::ceil(axis.lo / step - 1e-9)); double(i) * step <= axis.hi + 1e-9 * step; ++i)
        axis.ticks.push_back(double(i) * step);
    return axis;
}

struct Frame {
    double left, right, top, bottom;  // the plot area in pixels
    double width() const { return right - left; }
    double height() const { return bottom - top; }
};

// Legend items laid out in rows under the plot; returns the number of rows.
struct LegendItem {
    std::string name, color;
    int shape;  // 0-3: a line with that marker, 4: a line alone, -1: a bar swatch
    bool dashed;
};

std::vector<std::vector<size_t>> legend_rows(const std::vector<LegendItem>& items, double available) {
    std::vector<std::vector<size_t>> rows(1);
    double used = 0;
    for (size_t i = 0; i < items.size(); ++i) {
        const double w = 34.0 + text_width(items[i].name) + 14.0;
        if (!rows.back().empty() && used + w > available) {
            rows.emplace_back();
            used = 0;
        }
        rows.back().push_back(i);
        used += w;
    }
    return rows;
}

std::string marker(int shape, double x, double y, const std::string& color, const std::string& title) {
    const std::string inner = title.empty() ? "" : "<title>" + escape(title) + "</title>";
    const std::string close = title.empty() ? "/>" : ">" + inner;
    const std::string paint = " fill=\"" + color + "\" stroke=\"white\" stroke-width=\"1\"";
    switch (shape % 4) {
        case 0:
            return "<circle cx=\"" + num(x) + "\" cy=\"" + num(y) + "\" r=\"4.0\"" + paint + close +
                   (title.empty() ? "" : "</circle>");
        case 1:
            return "<rect x=\"" + num(x - 3.5) + "\" y=\"" + num(y - 3.5) + "\" width=\"7.0\" height=\"7.0\"" + paint +
                   close + (title.empty() ? "" : "</rect>");
        case 2:
            return "<path d=\"M" + num(x) + " " + num(y - 4.5) + "L" + num(x + 4.5) + " " + num(y + 3.5) + "L" +
                   num(x - 4.5) + " " + num(y + 3.5) + "Z\"" + paint + close + (title.empty() ? "" : "</path>");
        default:
            return "<path d=\"M" + num(x) + " " + num(y - 5.0) + "L" + num(x + 4.5) + " " + num(y) + "L" + num(x) +
                   " " + num(y + 5.0) + "L" + num(x - 4.5) + " " + num(y) + "Z\"" + paint + close +
                   (title.empty() ? "" : "</path>");
    }
}

std::string svg_open(int width, int height, const std::string& title) {
    std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) + "\" height=\"" +
                    std::to_string(height) + "\" viewBox=\"0 0 " + std::to_string(width) + " " +
                    std::to_string(height) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
    s += "<title>" + escape(title) + "</title>\n";
    s += "<rect x=\"0\" y=\"0\" width=\"" + std::to_string(width) + "\" height=\"" + std::to_string(height) +
         "\" fill=\"white\"/>\n";
    s += "<text x=\"" + num(width / 2.0) +
         "\" y=\"22.0\" text-anchor=\"middle\" font-size=\"15\" font-weight=\"bold\">" + escape(title) + "</text>\n";
    return s;
}

// Horizontal grid, y ticks and labels, the y axis title, the frame.
std::string y_axis(const Axis& axis, const Frame& f, const std::string& label) {
    std::string s = "<g class=\"y-axis\">\n";
    for (double t : axis.ticks) {
        const double y = f.bottom - (t - axis.lo) / (axis.hi - axis.lo) * f.height();
        s += "<line x1=\"" + num(f.left) + "\" y1=\"" + num(y) + "\" x2=\"" + num(f.right) + "\" y2=\"" + num(y) +
             "\" stroke=\"#e0e0e0\" stroke-width=\"1\"/>\n";
        s += "<line x1=\"" + num(f.left - 5) + "\" y1=\"" + num(y) + "\" x2=\"" + num(f.left) + "\" y2=\"" + num(y) +
             "\" stroke=\"#333333\" stroke-width=\"1\"/>\n";
        s += "<text x=\"" + num(f.left - 8) + "\" y=\"" + num(y + 4) + "\" text-anchor=\"end\" font-size=\"11\">" +
             format_fixed(t, axis.decimals) + "</text>\n";
    }
    const double cy = (f.top + f.bottom) / 2;
    s += "<text x=\"16.0\" y=\"" + num(cy) + "\" text-anchor=\"middle\" transform=\"rotate(-90 16.0 " + num(cy) +
         ")\">" + escape(label) + "</text>\n";
    s += "</g>\n";
    return s;
}

std::string frame_lines(const Frame& f) {
    return "<path d=\"M" + num(f.left) + " " + num(f.top) + "L" + num(f.left) + " " + num(f.bottom) + "L" +
           num(f.right) + " " + num(f.bottom) + "\" fill=\"none\" stroke=\"#333333\" stroke-width=\"1\"/>\n";
}

std::string legend(const std::vector<LegendItem>& items, const std::vector<std::vector<size_t>>& rows, double top,
                   int width) {
    std::string s = "<g class=\"legend\">\n";
    for (size_t r = 0; r < rows.size(); ++r) {
        double row_width = 0;
        for (size_t i : rows[r]) row_width += 34.0 + text_width(items[i].name) + 14.0;
        double x = std::max(4.0, (width - row_width) / 2);
        const double y = top + kLegendRow * double(r) + 9;
        for (size_t i : rows[r]) {
            const LegendItem& item = items[i];
            if (item.shape < 0) {
                s += "<rect x=\"" + num(x + 8) + "\" y=\"" + num(y - 6) + "\" width=\"14.0\" height=\"12.0\" fill=\"" +
                     item.color + "\"/>\n";
            } else {
                s += "<line x1=\"" + num(x) + "\" y1=\"" + num(y) + "\" x2=\"" + num(x + 28) + "\" y2=\"" + num(y) +
                     "\" stroke=\"" + item.color + "\" stroke-width=\"2\"" +
                     (item.dashed ? " stroke-dasharray=\"6 4\"" : "") + "/>\n";
                if (item.shape < 4) s += marker(item.shape, x + 14, y, item.color, "") + "\n";
            }
            s += "<text x=\"" + num(x + 34) + "\" y=\"" + num(y + 4) + "\">" + escape(item.name) + "</text>\n";
            x += 34.0 + text_width(item.name) + 14.0;
        }
    }
    s += "</g>\n";
    return s;
}

void check_size(int width, int height) {
    if (width < 200 || height < 150)
        throw std::invalid_argument("chart size " + std::to_string(width) + "x" + std::to_string(height) +
                                    " is below 200x150");
}

}  // namespace

std::string format_fixed(double value, int decimals) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
    std::string s = buffer;
    if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
    return s;
}

std::string render_line_chart(const LineChart& chart) {
    check_size(chart.width, chart.height);
    if (chart.series.empty()) throw std::invalid_argument(chart.title + ": a line chart needs at least one series");
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
    for (const LineSeries& s : chart.series) {
        if (s.x.size() != s.y.size())
            throw std::invalid_argument(chart.title + ": series " + s.name + " has " + std::to_string(s.x.size()) +
                                        " x values and " + std::to_string(s.y.size()) + " y values");
        for (size_t i = 0; i < s.x.size(); ++i) {
            if (!std::isfinite(s.x[i]))
                throw std::invalid_argument(chart.title + ": series " + s.name + " has a non-finite x");
            if (chart.log_x && !(s.x[i] > 0))
                throw std::invalid_argument(chart.title + ": a logarithmic x axis needs positive x values");
            if (!std::isfinite(s.y[i])) continue;
            xmin = std::min(xmin, s.x[i]);
            xmax = std::max(xmax, s.x[i]);
            ymin = std::min(ymin, s.y[i]);
            ymax = std::max(ymax, s.y[i]);
        }
    }
    if (!std::isfinite(xmin)) throw std::invalid_argument(chart.title + ": no finite points to draw");

    // x axis: explicit ticks, decades on a log axis, or nice linear steps.
    Axis xa;
    xa.log = chart.log_x;
    if (!chart.x_ticks.empty() || chart.log_x) {
        std::vector<double> ticks = chart.x_ticks;
        if (ticks.empty())
            for (double p = std::floor(std::log10(xmin)); p <= std::ceil(std::log10(xmax)); p += 1)
                ticks.push_back(std::pow(10.0, p));
        double lo = xa.to_unit(xmin), hi = xa.to_unit(xmax);
        for (double t : ticks) {
            if (chart.log_x && !(t > 0))
                throw std::invalid_argument(chart.title + ": a logarithmic x axis needs positive ticks");
            lo = std::min(lo, xa.to_unit(t));
            hi = std::max(hi, xa.to_unit(t));
        }
        if (!(hi > lo)) {
            lo -= 0.5;
            hi += 0.5;
        }
        const double pad = 0.05 * (hi - lo);
        xa.lo = lo - pad;
        xa.hi = hi + pad;
        xa.ticks = ticks;
        xa.decimals = chart.x_ticks.empty() ? 0 : chart.x_tick_decimals;
    } else {
        xa = linear_axis(xmin, xmax, 6, true, false);
    }
    if (ymax - ymin < chart.min_y_span) {
        const double mid = (ymin + ymax) / 2;
        ymin = mid - chart.min_y_span / 2;
        ymax = mid + chart.min_y_span / 2;
    }
    const Axis ya = linear_axis(ymin, ymax, 5, true);

    // Legend under the plot, then the layout.
    std::vector<LegendItem> items;
    for (size_t i = 0; i < chart.series.size(); ++i)
        items.push_back({chart.series[i].name, kPalette[i % kPaletteSize], chart.series[i].markers ? int(i % 4) : 4,
                         chart.series[i].dashed});  // 4: line only
    const auto rows = legend_rows(items, chart.width - 8.0);
    const double legend_height = kLegendRow * double(rows.size());
    const Frame f{64.0, chart.width - 20.0, 40.0, chart.height - 48.0 - legend_height};
    if (f.height() < 40 || f.width() < 40)
        throw std::invalid_argument(chart.title + ": too many series for the chart size");
    const auto px = [&](double x) { return f.left + (xa.to_unit(x) - xa.lo) / (xa.hi - xa.lo) * f.width(); };
    const auto py = [&](double y) { return f.bottom - (y - ya.lo) / (ya.hi - ya.lo) * f.height(); };

    std::string s = svg_open(chart.width, chart.height, chart.title);
    s += y_axis(ya, f, chart.y_label);
    s += "<g class=\"x-axis\">\n";
    for (double t : xa.ticks) {
        const double x = px(t);
        s += "<line x1=\"" + num(x) + "\" y1=\"" + num(f.bottom) + "\" x2=\"" + num(x) + "\" y2=\"" +
             num(f.bottom + 5) + "\" stroke=\"#333333\" stroke-width=\"1\"/>\n";
        s += "<text x=\"" + num(x) + "\" y=\"" + num(f.bottom + 18) + "\" text-anchor=\"middle\" font-size=\"11\">" +
             (chart.x_ticks.empty() && chart.log_x ? format_trimmed(t) : format_fixed(t, xa.decimals)) + "</text>\n";
    }
    s += "<text x=\"" + num((f.left + f.right) / 2) + "\" y=\"" + num(f.bottom + 36) + "\" text-anchor=\"middle\">" +
         escape(chart.x_label) + "</text>\n";
    s += "</g>\n";
    s += frame_lines(f);

    for (size_t i = 0; i < chart.series.size(); ++i) {
        const LineSeries& series = chart.series[i];
        const std::string color = kPalette[i % kPaletteSize];
        s += "<g class=\"series\">\n";
        std::string points;
        for (size_t p = 0; p < series.x.size(); ++p) {
            if (!std::isfinite(series.y[p])) continue;
            if (!points.empty()) points += " ";
            points += num(px(series.x[p])) + "," + num(py(series.y[p]));
        }
        s += "<polyline fill=\"none\" stroke=\"" + color + "\" stroke-width=\"2\"" +
             (series.dashed ? " stroke-dasharray=\"6 4\"" : "") + " points=\"" + points + "\"><title>" +
             escape(series.name) + "</title></polyline>\n";
        if (series.markers)
            for (size_t p = 0; p < series.x.size(); ++p) {
                if (!std::isfinite(series.y[p])) continue;
                s +=
                    marker(int(i % 4), px(series.x[p]), py(series.y[p]), color,
                           series.name + ": x=" + format_trimmed(series.x[p]) + ", y=" + format_fixed(series.y[p], 3)) +
                    "\n";
            }
        s += "</g>\n";
    }
    s += legend(items, rows, chart.height - 8.0 - legend_height, chart.width);
    s += "</svg>\n";
    return s;
}

std::string render_bar_chart(const BarChart& chart) {
    check_size(chart.width, chart.height);
    if (chart.series.empty() || chart.categories.empty())
        throw std::invalid_argument(chart.title + ": a bar chart needs at least one series and one category");
    double ymax = -std::numeric_limits<double>::infinity();
    for (const BarSeries& s : chart.series) {
        if (s.values.size() != chart.categories.size())
            throw std::invalid_argument(chart.title + ": series " + s.name + " has " + std::to_string(s.values.size()) +
                                        " values for " + std::to_string(chart.categories.size()) + " categories");
        for (double v : s.values)
            if (std::isfinite(v)) ymax = std::max(ymax, v);
    }
    if (!std::isfinite(ymax)) throw std::invalid_argument(chart.title + ": no finite values to draw");
    if (!std::isfinite(chart.baseline)) throw std::invalid_argument(chart.title + ": the baseline must be finite");
    Axis ya = linear_axis(chart.baseline,
                          std::max(ymax, chart.baseline) * 1.0 + 0.03 * std::fabs(ymax - chart.baseline), 5, false);
    // The axis starts at the baseline itself, not at a step below it.
    if (ya.lo < chart.baseline) {
        ya.lo = chart.baseline;
        ya.ticks.erase(
            std::remove_if(ya.ticks.begin(), ya.ticks.end(), [&](double t) { return t < chart.baseline - 1e-12; }),
            ya.ticks.end());
    }

    std::vector<LegendItem> items;
    for (size_t i = 0; i < chart.series.size(); ++i)
        items.push_back({chart.series[i].name, kPalette[i % kPaletteSize], -1, false});
    const auto rows = legend_rows(items, chart.width - 8.0);
    const double legend_height = kLegendRow * double(rows.size());

    // Category labels: horizontal when each fits its group, else rotated by 35 degrees.
    const double plot_width = chart.width - 20.0 - 64.0;
    const double group = plot_width / double(chart.categories.size());
    double longest = 0;
    for (const std::string& c : chart.categories) longest = std::max(longest, text_width(c));
    const bool rotate = longest > group - 4;
    const double label_height = rotate ? longest * 0.574 + 8 /* sin 35 degrees */ : 0;
    const Frame f{64.0, chart.width - 20.0, 40.0, chart.height - 48.0 - legend_height - label_height};
    if (f.height() < 40)
        throw std::invalid_argument(chart.title + ": too many series or too long labels for the chart size");
    const auto py = [&](double y) {
        const double c = std::clamp(y, ya.lo, ya.hi);
        return f.bottom - (c - ya.lo) / (ya.hi - ya.lo) * f.height();
    };

    std::string s = svg_open(chart.width, chart.height, chart.title);
    s += y_axis(ya, f, chart.y_label);
    const double bar = group * 0.8 / double(chart.series.size());
    for (size_t i = 0; i < chart.series.size(); ++i) {
        const BarSeries& series = chart.series[i];
        s += "<g class=\"series\" fill=\"" + std::string(kPalette[i % kPaletteSize]) + "\">\n";
        for (size_t c = 0; c < chart.categories.size(); ++c) {
            const double v = series.values[c];
            if (!std::isfinite(v)) continue;
            const double x = f.left + group * double(c) + group * 0.1 + bar * double(i);
            const double top = std::min(py(v), py(chart.baseline)), height = std::fabs(py(chart.baseline) - py(v));
            s += "<rect x=\"" + num(x) + "\" y=\"" + num(top) + "\" width=\"" + num(bar) + "\" height=\"" +
                 num(height) + "\"><title>" +
                 escape(series.name + ", " + chart.categories[c] + ": " + format_fixed(v, 3)) + "</title></rect>\n";
        }
        s += "</g>\n";
    }
    s += "<g class=\"x-axis\">\n";
    for (size_t c = 0; c < chart.categories.size(); ++c) {
        const double x = f.left + group * (double(c) + 0.5);
        if (rotate)
            s += "<text x=\"" + num(x) + "\" y=\"" + num(f.bottom + 14) +
                 "\" text-anchor=\"end\" font-size=\"11\" "
                 "transform=\"rotate(-35 " +
                 num(x) + " " + num(f.bottom + 14) + ")\">" + escape(chart.categories[c]) + "</text>\n";
        else
            s += "<text x=\"" + num(x) + "\" y=\"" + num(f.bottom + 16) +
                 "\" text-anchor=\"middle\" font-size=\"11\">" + escape(chart.categories[c]) + "</text>\n";
    }
    s += "<text x=\"" + num((f.left + f.right) / 2) + "\" y=\"" + num(f.bottom + (rotate ? label_height + 18 : 34)) +
         "\" text-anchor=\"middle\">" + escape(chart.x_label) + "</text>\n";
    s += "</g>\n";
    s += frame_lines(f);
    s += legend(items, rows, chart.height - 8.0 - legend_height, chart.width);
    s += "</svg>\n";
    return s;
}

}  // namespace animorder::results
