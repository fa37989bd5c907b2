#include "services/flightplan/scan_pattern.hpp"

#include <algorithm>
#include <cmath>

namespace airseg::flightplan {

ScanPattern::ScanPattern(std::vector<Enu> polygon, double spacing, double heading_deg, double step,
                         double min_spacing, std::uint64_t max_work)
    : polygon_(std::move(polygon)), spacing_(spacing), step_(step), min_spacing_(min_spacing) {
    const double h = heading_deg * kPi / 180.0;
    along_ = {std::sin(h), std::cos(h)};
    across_ = {std::cos(h), -std::sin(h)};
    rotated_.reserve(polygon_.size());
    vmin_ = INFINITY;
    vmax_ = -INFINITY;
    for (const Enu p : polygon_) {
        const Enu r{p.e * along_.e + p.n * along_.n, p.e * across_.e + p.n * across_.n};
        rotated_.push_back(r);
        vmin_ = std::min(vmin_, r.n);
        vmax_ = std::max(vmax_, r.n);
    }
    if (rotated_.size() < 3 || !(spacing_ > 0.0) || !(vmax_ > vmin_)) {
        return;
    }
    const double lines = std::ceil((vmax_ - vmin_) / spacing_ - 1e-9);
    work_ = std::max(1.0, lines) * static_cast<double>(rotated_.size());
    if (lines > static_cast<double>(kMaxLines) || work_ > static_cast<double>(max_work)) {
        too_many_lines_ = true;
        return;
    }
    lines_ = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(lines));
    for (std::uint64_t k = 0; k < lines_; ++k) {
        total_ += line(k).count;
    }
}

ScanPattern::Line ScanPattern::line(std::uint64_t k) const {
    Line out;
    const double margin = std::min(1e-6, (vmax_ - vmin_) / 4.0);
    out.v = std::clamp(vmin_ + (static_cast<double>(k) + 0.5) * spacing_, vmin_ + margin, vmax_ - margin);
    double lo = INFINITY, hi = -INFINITY;
    const std::size_t n = rotated_.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Enu a = rotated_[i], b = rotated_[(i + 1) % n];
        if ((a.n <= out.v) == (b.n <= out.v)) {
            continue;  // half-open rule: a vertex is counted once
        }
        const double u = a.e + (out.v - a.n) * (b.e - a.e) / (b.n - a.n);
        lo = std::min(lo, u);
        hi = std::max(hi, u);
    }
    if (!(hi >= lo)) {
        return out;
    }
    out.u0 = lo;
    out.u1 = hi;
    const double len = hi - lo;
    if (len < min_spacing_) {
        out.count = 1;
    } else if (step_ > 0.0) {
        out.count = static_cast<std::uint64_t>(std::ceil(len / step_ - 1e-9)) + 1;
    } else {
        out.count = 2;
    }
    return out;
}

Enu ScanPattern::point(std::uint64_t k, const Line& line, std::uint64_t j) const {
    const double t = line.count <= 1 ? 0.5 : static_cast<double>(j) / static_cast<double>(line.count - 1);
    const double len = line.u1 - line.u0;
    const double u = (k % 2 == 0) ? line.u0 + t * len : line.u1 - t * len;
    return {u * along_.e + line.v * across_.e, u * along_.n + line.v * across_.n};
}

}  // namespace airseg::flightplan
