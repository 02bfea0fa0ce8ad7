#include "place_planner/validation/plot.h"
#include "place_planner/infra/output_file.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace place_planner {
namespace validation {
namespace {

const cv::Scalar kBlack(0, 0, 0), kGrey(200, 200, 200), kWhite(255, 255, 255);
// Tableau-like palette (BGR).
const cv::Scalar kPalette[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44},  {40, 39, 214},
                               {189, 103, 148}, {75, 86, 140},  {194, 119, 227}, {127, 127, 127},
                               {34, 189, 188},  {0, 0, 0}};
constexpr size_t kColours = sizeof(kPalette) / sizeof(kPalette[0]);
const int kFont = cv::FONT_HERSHEY_SIMPLEX;

std::string num(double v) {
  char b[32];
  if (std::abs(v) >= 100 || v == std::floor(v)) std::snprintf(b, sizeof b, "%.0f", v);
  else if (std::abs(v) >= 1) std::snprintf(b, sizeof b, "%.1f", v);
  else std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

double niceStep(double range, int ticks) {
  const double raw = range / std::max(1, ticks);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

struct Frame {
  cv::Mat img;
  cv::Rect box;  // plot area
  double x0, x1, y0, y1;
  cv::Point at(double x, double y) const {
    return {box.x + static_cast<int>(std::lround((x - x0) / (x1 - x0) * box.width)),
            box.y + box.height - static_cast<int>(std::lround((y - y0) / (y1 - y0) * box.height))};
  }
};

Frame axes(const std::string& title, const std::string& y_label, double y0, double y1, int w,
           int h) {
  Frame f;
  f.img = cv::Mat(h, w, CV_8UC3, kWhite);
  f.box = cv::Rect(90, 50, w - 90 - 230, h - 50 - 110);
  f.x0 = 0;
  f.x1 = 1;
  f.y0 = y0;
  f.y1 = y1;
  cv::putText(f.img, title, {f.box.x, 30}, kFont, 0.7, kBlack, 2, cv::LINE_AA);
  const double step = niceStep(y1 - y0, 6);
  for (double y = std::ceil(y0 / step) * step; y <= y1 + 1e-9; y += step) {
    const cv::Point p = f.at(0, y);
    cv::line(f.img, {f.box.x, p.y}, {f.box.x + f.box.width, p.y}, kGrey, 1);
    cv::putText(f.img, num(y), {8, p.y + 5}, kFont, 0.45, kBlack, 1, cv::LINE_AA);
  }
  cv::rectangle(f.img, f.box, kBlack, 1);
  // Vertical y label, drawn then rotated.
  cv::Mat lab(24, 400, CV_8UC3, kWhite);
  cv::putText(lab, y_label, {2, 18}, kFont, 0.5, kBlack, 1, cv::LINE_AA);
  cv::Mat rot;
  cv::rotate(lab, rot, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int top = std::max(0, f.box.y + f.box.height / 2 - 200);
  const int rows = std::min(rot.rows, f.img.rows - top);
  rot(cv::Rect(0, rot.rows - rows, rot.cols, rows)).copyTo(f.img(cv::Rect(52, top, rot.cols, rows)));
  return f;
}

void legend(Frame& f, const std::vector<Series>& series) {
  int y = f.box.y + 10;
  const int x = f.box.x + f.box.width + 30;
  for (size_t i = 0; i < series.size(); ++i) {
    const cv::Scalar c = kPalette[i % kColours];
    cv::rectangle(f.img, {x, y - 8}, {x + 20, y + 4}, c, cv::FILLED);
    cv::putText(f.img, series[i].name, {x + 28, y + 4}, kFont, 0.45, kBlack, 1, cv::LINE_AA);
    y += 22;
  }
}

// By the output-file rules (infra/output_file.h): imwrite writes a temporary file beside the
// target (same extension: the format), which then replaces it.
void save(const std::string& path, const cv::Mat& img) {
  produceOutputFile(path, [&](const std::string& temp) {
    if (!cv::imwrite(temp, img)) throw std::runtime_error("cannot write " + path);
  });
}

}  // namespace

void plotLines(const std::string& path, const std::string& title, const std::string& x_label,
               const std::string& y_label, const std::vector<double>& x,
               const std::vector<Series>& series) {
  double ymax = 0;
  for (const auto& s : series)
    for (double v : s.y)
      if (std::isfinite(v)) ymax = std::max(ymax, v);
  if (ymax <= 0) ymax = 1;
  const double ystep = niceStep(ymax * 1.05, 6);
  Frame f = axes(title, y_label, 0, std::ceil(ymax * 1.05 / ystep) * ystep, 960, 560);
  f.x0 = x.empty() ? 0 : *std::min_element(x.begin(), x.end());
  f.x1 = x.empty() ? 1 : *std::max_element(x.begin(), x.end());
  if (f.x1 <= f.x0) f.x1 = f.x0 + 1;
  const double pad = 0.04 * (f.x1 - f.x0);
  f.x0 -= pad;
  f.x1 += pad;
  const double xstep = niceStep(f.x1 - f.x0, 8);
  for (double v = std::ceil(f.x0 / xstep) * xstep; v <= f.x1; v += xstep) {
    const cv::Point p = f.at(v, f.y0);
    cv::line(f.img, p, {p.x, p.y + 5}, kBlack, 1);
    cv::putText(f.img, num(v), {p.x - 14, p.y + 22}, kFont, 0.45, kBlack, 1, cv::LINE_AA);
  }
  cv::putText(f.img, x_label, {f.box.x + f.box.width / 2 - 120, f.box.y + f.box.height + 50}, kFont,
              0.55, kBlack, 1, cv::LINE_AA);
  for (size_t i = 0; i < series.size(); ++i) {
    const cv::Scalar c = kPalette[i % kColours];
    bool have_prev = false;
    cv::Point prev;
    for (size_t k = 0; k < x.size() && k < series[i].y.size(); ++k) {
      if (!std::isfinite(series[i].y[k])) {
        have_prev = false;
        continue;
      }
      const cv::Point p = f.at(x[k], series[i].y[k]);
      if (have_prev) cv::line(f.img, prev, p, c, 2, cv::LINE_AA);
      cv::circle(f.img, p, 4, c, cv::FILLED, cv::LINE_AA);
      prev = p;
      have_prev = true;
    }
  }
  legend(f, series);
  save(path, f.img);
}

void plotBars(const std::string& path, const std::string& title, const std::string& y_label,
              const std::vector<std::string>& labels, const std::vector<Series>& series,
              double y_min, double y_max, double reference_line) {
  const int n = static_cast<int>(labels.size());
  const int w = std::max(700, 320 + n * std::max(18, 8 * static_cast<int>(series.size()) + 6));
  // Plot area above, 260 px below it for the rotated group labels.
  Frame a;
  a.img = cv::Mat(840, w, CV_8UC3, kWhite);
  a.box = cv::Rect(90, 50, w - 90 - 230, 840 - 50 - 260);
  a.x0 = 0;
  a.x1 = std::max(1, n);
  a.y0 = y_min;
  a.y1 = y_max;
  cv::putText(a.img, title, {a.box.x, 30}, kFont, 0.7, kBlack, 2, cv::LINE_AA);
  const double step = niceStep(y_max - y_min, 6);
  for (double y = std::ceil(y_min / step) * step; y <= y_max + 1e-9; y += step) {
    const cv::Point p = a.at(0, y);
    cv::line(a.img, {a.box.x, p.y}, {a.box.x + a.box.width, p.y}, kGrey, 1);
    cv::putText(a.img, num(y), {8, p.y + 5}, kFont, 0.45, kBlack, 1, cv::LINE_AA);
  }
  cv::putText(a.img, y_label, {8, a.box.y - 12}, kFont, 0.45, kBlack, 1, cv::LINE_AA);
  const int ns = std::max<int>(1, static_cast<int>(series.size()));
  for (int k = 0; k < n; ++k) {
    for (int s = 0; s < static_cast<int>(series.size()); ++s) {
      if (k >= static_cast<int>(series[s].y.size()) || !std::isfinite(series[s].y[k])) continue;
      const double xl = k + 0.1 + 0.8 * s / ns, xr = k + 0.1 + 0.8 * (s + 1) / ns;
      const double v = std::clamp(series[s].y[k], y_min, y_max);
      cv::rectangle(a.img, a.at(xl, y_min), a.at(xr, v), kPalette[s % kColours], cv::FILLED);
    }
    // Label rotated 90 degrees under the group.
    cv::Mat lab(16, 250, CV_8UC3, kWhite);
    cv::putText(lab, labels[k], {2, 12}, kFont, 0.38, kBlack, 1, cv::LINE_AA);
    cv::Mat rot;
    cv::rotate(lab, rot, cv::ROTATE_90_COUNTERCLOCKWISE);
    const cv::Point base = a.at(k + 0.5, y_min);
    const int x = std::clamp(base.x - 8, 0, a.img.cols - rot.cols);
    rot.copyTo(a.img(cv::Rect(x, base.y + 4, rot.cols, rot.rows)));
  }
  if (reference_line > y_min && reference_line < y_max) {
    const cv::Point p = a.at(0, reference_line);
    cv::line(a.img, {a.box.x, p.y}, {a.box.x + a.box.width, p.y}, kBlack, 1, cv::LINE_AA);
    cv::putText(a.img, "target " + num(reference_line), {a.box.x + 4, p.y - 4}, kFont, 0.4, kBlack,
                1, cv::LINE_AA);
  }
  cv::rectangle(a.img, a.box, kBlack, 1);
  legend(a, series);
  save(path, a.img);
}

void renderPlacement(const std::string& path, const Mesh& area_W, const Mesh& object_O, const Eigen::Isometry3d& X_WO,
                     const Eigen::Vector3d& view, const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                     double radius, int width, int height) {
  const Eigen::Vector3d d = view.normalized();
  // Image axes: right = up x d... with up the world's z where it is not along the view.
  const Eigen::Vector3d world_up = std::abs(d.z()) < 0.95 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d right = d.cross(world_up).normalized(), up = right.cross(d);
  const Eigen::Vector3d centre = X_WO * object_O.properties.center_of_mass;
  struct Tri {
    std::array<Eigen::Vector3d, 3> p;
    cv::Scalar colour;
  };
  std::vector<Tri> tris;
  auto add = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const cv::Scalar& base) {
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-15) return;
    n.normalize();
    const Eigen::Vector3d light = (-d + 0.6 * up).normalized();
    const double shade = 0.35 + 0.65 * std::abs(n.dot(light));
    tris.push_back({{a, b, c}, base * shade});
  };
  for (const auto& t : area_W.triangles) {
    const Eigen::Vector3d &a = area_W.vertices[t[0]], &b = area_W.vertices[t[1]], &c = area_W.vertices[t[2]];
    if ((a - centre).norm() > radius && (b - centre).norm() > radius && (c - centre).norm() > radius) continue;
    add(a, b, c, cv::Scalar(200, 200, 200));
  }
  for (const auto& t : object_O.triangles)
    add(X_WO * object_O.vertices[t[0]], X_WO * object_O.vertices[t[1]], X_WO * object_O.vertices[t[2]],
        cv::Scalar(40, 140, 245));  // BGR: orange
  // Fit: the object and its approach with a margin, the area around them.
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  auto fit = [&](const Eigen::Vector3d& q) {
    const double x = (q - centre).dot(right), y = (q - centre).dot(up);
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  };
  for (const auto& v : object_O.vertices) fit(X_WO * v);
  fit(from);
  fit(to);
  const double margin = 0.25 * std::max(x1 - x0, y1 - y0) + 0.02;
  x0 -= margin, x1 += margin, y0 -= margin, y1 += margin;
  const double scale = std::min(width / (x1 - x0), height / (y1 - y0));
  auto pixel = [&](const Eigen::Vector3d& q) {
    const double x = (q - centre).dot(right), y = (q - centre).dot(up);
    return cv::Point(static_cast<int>(std::lround(0.5 * width + (x - 0.5 * (x0 + x1)) * scale)),
                     static_cast<int>(std::lround(0.5 * height - (y - 0.5 * (y0 + y1)) * scale)));
  };
  // Depth buffer: each pixel keeps the nearest triangle along the view.
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<double> depth(static_cast<size_t>(width) * height, std::numeric_limits<double>::infinity());
  for (const Tri& t : tris) {
    Eigen::Vector3d q[3];  // pixel x, y and depth
    for (int k = 0; k < 3; ++k) {
      const cv::Point2d p((t.p[k] - centre).dot(right), (t.p[k] - centre).dot(up));
      q[k] = Eigen::Vector3d(0.5 * width + (p.x - 0.5 * (x0 + x1)) * scale, 0.5 * height - (p.y - 0.5 * (y0 + y1)) * scale,
                             t.p[k].dot(d));
    }
    const double area = (q[1].x() - q[0].x()) * (q[2].y() - q[0].y()) - (q[1].y() - q[0].y()) * (q[2].x() - q[0].x());
    if (std::abs(area) < 1e-12) continue;
    const int xa = std::max(0, static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}))));
    const int xb = std::min(width - 1, static_cast<int>(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}))));
    const int ya = std::max(0, static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}))));
    const int yb = std::min(height - 1, static_cast<int>(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}))));
    for (int y = ya; y <= yb; ++y)
      for (int x = xa; x <= xb; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double w0 = ((q[1].x() - px) * (q[2].y() - py) - (q[1].y() - py) * (q[2].x() - px)) / area;
        const double w1 = ((q[2].x() - px) * (q[0].y() - py) - (q[2].y() - py) * (q[0].x() - px)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double z = w0 * q[0].z() + w1 * q[1].z() + w2 * q[2].z();
        double& best = depth[static_cast<size_t>(y) * width + x];
        if (z >= best) continue;
        best = z;
        img.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(t.colour[0]), cv::saturate_cast<uchar>(t.colour[1]),
                                            cv::saturate_cast<uchar>(t.colour[2]));
      }
  }
  if ((to - from).norm() > 1e-6)
    cv::arrowedLine(img, pixel(from), pixel(to), cv::Scalar(200, 90, 20), 3, cv::LINE_AA, 0, 0.08);
  save(path, img);
}

}  // namespace validation
}  // namespace place_planner
