// Small PNG charts for the benchmark (OpenCV drawing, no plotting library needed).
#pragma once
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "place_planner/model/mesh.h"

namespace place_planner {
namespace validation {

struct Series {
  std::string name;
  std::vector<double> y;  // one per x value; NaN leaves a gap
};

// Line chart: every series against x, with markers, axes, ticks and a legend.
// Throws std::runtime_error when the file cannot be written.
void plotLines(const std::string& path, const std::string& title, const std::string& x_label,
               const std::string& y_label, const std::vector<double>& x,
               const std::vector<Series>& series);

// Grouped bar chart: one group per label, one bar per series; y axis from y_min to y_max.
void plotBars(const std::string& path, const std::string& title, const std::string& y_label,
              const std::vector<std::string>& labels, const std::vector<Series>& series,
              double y_min, double y_max, double reference_line = -1.0);

// A picture of a placement: the area (grey) and the object at X_WO (orange), flat shaded and
// drawn far to near, seen along `view` (W, orthographic), and an arrow (blue) from `from` to
// `to` (W: the approach). Only area triangles within `radius` of the object's centre are drawn.
void renderPlacement(const std::string& path, const Mesh& area_W, const Mesh& object_O,
                     const Eigen::Isometry3d& X_WO, const Eigen::Vector3d& view, const Eigen::Vector3d& from,
                     const Eigen::Vector3d& to, double radius = 0.25, int width = 800, int height = 600);

}  // namespace validation
}  // namespace place_planner
