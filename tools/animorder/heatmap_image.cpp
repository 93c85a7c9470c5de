#include "heatmap_image.h"

#include <stb_easy_font.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace animorder::tool {
namespace {

using Rgb = std::array<uint8_t, 3>;

// A perceptually ordered scale (dark blue → teal → yellow → red) sampled at 6 stops.
Rgb scale_colour(double t) {
    static const double stops[6][3] = {{48, 18, 59},   {40, 120, 230}, {30, 200, 160},
                                       {160, 230, 60}, {250, 170, 30}, {200, 30, 10}};
    t = std::clamp(t, 0.0, 1.0) * 5.0;
    const int i = std::min(4, int(t));
    const double f = t - i;
    Rgb c;
    for (int k = 0; k < 3; ++k) c[k] = uint8_t(std::lround(stops[i][k] * (1 - f) + stops[i + 1][k] * f));
    return c;
}

class Canvas {
public:
    Canvas(int w, int h, Rgb fill) : w_(w), h_(h), pixels_(size_t(w) * h * 3) {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) set(x, y, fill);
    }
    void set(int x, int y, Rgb c) {
        if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
        std::copy(c.begin(), c.end(), pixels_.begin() + (size_t(y) * w_ + x) * 3);
    }
    void rect(int x0, int y0, int x1, int y1, Rgb c) {
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) set(x, y, c);
    }
    // Text with stb_easy_font (its quads are axis-aligned rectangles), scaled up.
    void text(int x, int y, const std::string& s, Rgb c, int scale = 2) {
        static char buffer[60000];
        const int quads = stb_easy_font_print(0, 0, const_cast<char*>(s.c_str()), nullptr, buffer, sizeof buffer);
        const float* v = reinterpret_cast<const float*>(buffer);
        for (int q = 0; q < quads; ++q) {
            const float* quad = v + q * 16;  // 4 vertices of (x, y, z, colour)
            const float qx0 = quad[0], qy0 = quad[1], qx1 = quad[8], qy1 = quad[9];
            rect(x + int(qx0 * scale), y + int(qy0 * scale), x + int(qx1 * scale), y + int(qy1 * scale), c);
        }
    }
    std::string png() const {
        std::string out;
        auto sink = [](void* context, void* data, int size) {
            static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
        };
        if (!stbi_write_png_to_func(sink, &out, w_, h_, 3, pixels_.data(), w_ * 3))
            throw std::runtime_error("PNG encoding failed");
        return out;
    }

private:
    int w_, h_;
    std::vector<uint8_t> pixels_;
};

}  // namespace

std::string heatmap_png(const std::vector<uint32_t>& counts, unsigned resolution, const std::string& caption) {
    const uint32_t max_count = std::max<uint32_t>(4, *std::max_element(counts.begin(), counts.end()));
    const int margin = 16, legend = 110, caption_h = 40;
    const int r = int(resolution);
    // The legend: one swatch per count value (or per evenly spaced value when there are many), each
    // at least as tall as its label (stb_easy_font's line is 12 units, drawn at twice that).
    const uint32_t steps = std::min<uint32_t>(max_count, 12);
    const int swatch = std::max(16, std::min(28, (r - 30) / int(steps)));
    const int legend_h = 24 + int(steps) * swatch;
    // The image grows past the picture where the caption or the legend would not fit (small
    // resolutions): nothing is cut off.
    const int caption_w = 2 * stb_easy_font_width(const_cast<char*>(caption.c_str()));
    Canvas canvas(std::max(r + 2 * margin + legend, caption_w + 2 * margin),
                  std::max(r, legend_h) + 2 * margin + caption_h, {255, 255, 255});
    const Rgb background{235, 235, 235};
    for (int y = 0; y < r; ++y)
        for (int x = 0; x < r; ++x) {
            const uint32_t c = counts[size_t(y) * r + x];
            canvas.set(margin + x, margin + caption_h + y,
                       c == 0 ? background : scale_colour(double(c - 1) / double(max_count - 1)));
        }
    canvas.text(margin, 10, caption, {0, 0, 0});

    const int x0 = margin + r + 24, top = margin + caption_h;
    canvas.text(x0, top - 2, "shaded", {0, 0, 0}, 1);
    canvas.text(x0, top + 8, "per pixel", {0, 0, 0}, 1);
    for (uint32_t i = 0; i < steps; ++i) {
        const uint32_t value =
            1 + uint32_t(std::lround(double(i) * (max_count - 1) / double(std::max<uint32_t>(1, steps - 1))));
        const int y = top + 24 + int(i) * swatch;
        canvas.rect(x0, y, x0 + 20, y + swatch - 2, scale_colour(double(value - 1) / double(max_count - 1)));
        canvas.text(x0 + 26, y + swatch / 2 - 6, std::to_string(value), {0, 0, 0});
    }
    return canvas.png();
}

}  // namespace animorder::tool
