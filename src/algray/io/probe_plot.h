// The probe plot: P*(t) along one ray with its isolating intervals and roots, as SVG or PNG.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "algray/io/drawing.h"
#include "algray/io/image_io.h"

namespace algray {

struct PlotMarker {
  enum class Kind { IsolationEnd, Root, ReferenceRoot };
  Kind kind;
  double t;
  std::string label;  // e.g. "lo", "root (bernstein+brent)", "solver_ref simple"; empty: named after the kind
};

// The paper's Figs. 5 and 8: P*(t) on [t_in, t_out] with its isolating intervals and roots.
struct ProbePlot {
  std::string title;           // one line, shown on top
  double t_in = 0, t_out = 1;  // the horizontal range; t_in == t_out is widened a little
  // Samples of P*(t), increasing t, same length. Values may be 0, huge or tiny; non-finite ones break the curve.
  std::vector<double> t, value;
  std::vector<std::pair<double, double>> intervals;  // isolating intervals to shade, in t
  std::vector<PlotMarker> markers;                   // drawn in this order within each kind
};

// Where the plot puts things, in pixels of the PNG (which are the SVG's user units), so that tools and tests
// can find a feature without re-deriving the layout.
struct ProbePlotGeometry {
  int width = 0, height = 0;                        // the whole picture
  double left = 0, top = 0, right = 0, bottom = 0;  // the plot area
  double t_in = 0, t_out = 1;                       // mapped onto left..right
  double y_min = -1, y_max = 1;                     // in scaled units, mapped onto bottom..top
  double floor = 1;                                 // of the vertical scale, see signed_log_floor

  double x_of(double t) const;
  // Applies the sign-preserving log scale, then maps to a pixel row.
  double y_of(double value) const;
};

// The vertical scale is y = sign(v) * log10(1 + |v| / floor): logarithmic for |v| >> floor, linear through 0,
// so sign changes stay visible however small the values near a root are. The floor is the smallest nonzero
// finite |v| among the values, raised to 1e-12 of the largest: samples right at a root can be 1e-300, and
// letting them set the floor would spend the whole height on decades of noise. 1 when no value is nonzero.
double signed_log_floor(const std::vector<double>& values);

ProbePlotGeometry probe_plot_geometry(const ProbePlot& plot);
// The same picture two ways; both throw OutputError on inconsistent input (t and value of different lengths,
// non-finite or reversed range).
std::string probe_plot_svg(const ProbePlot& plot);   // a standalone SVG 1.1 document
FrameImage probe_plot_image(const ProbePlot& plot);  // linear RGBA, text in a built-in capitals-only font
// Throws OutputError unless the name ends in .svg or .png (any case).
void check_probe_plot_path(const std::filesystem::path& path);
// .svg or .png by extension (case-insensitive), anything else throws OutputError; written atomically.
void write_probe_plot(const std::filesystem::path& path, const ProbePlot& plot);

// Exposed so that tests and tools can find the curve and the markers in the picture by their colour.
Rgb8 probe_curve_colour();
Rgb8 marker_colour(PlotMarker::Kind kind);

}  // namespace algray
