// AAF (eq. 2), FSF (eq. 4) and MAAF (eq. 9) as Fourier-plane functions; see fourier_filters.h
// for the width and normalisation conventions.
#include "analysis/fourier_filters.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace wedge::analysis {

namespace {
constexpr double kTwoPi = 6.283185307179586476925;
// Gaussians are cut where they fall below exp(-kCut^2 / 2), far under double precision of a sum.
constexpr double kCut = 9.0;
}  // namespace

std::string toString(FilterKind kind) {
    switch (kind) {
    case FilterKind::Aaf: return "aaf";
    case FilterKind::Fsf: return "fsf";
    case FilterKind::Maaf: return "maaf";
    }
    return "?";
}

std::string toString(FilterShape shape) { return shape == FilterShape::Box ? "box" : "gaussian"; }

FilterKind parseFilterKind(const std::string& text) {
    if (text == "aaf") return FilterKind::Aaf;
    if (text == "fsf") return FilterKind::Fsf;
    if (text == "maaf") return FilterKind::Maaf;
    throw Error("--filter", "expected aaf, fsf or maaf, got '" + text + "'");
}

FilterShape parseFilterShape(const std::string& text) {
    if (text == "box") return FilterShape::Box;
    if (text == "gaussian") return FilterShape::Gaussian;
    throw Error("--shape", "expected box or gaussian, got '" + text + "'");
}

namespace {
std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}
}  // namespace

void validateWedge(const DoubleWedge& w) {
    if (!(std::isfinite(w.sMin) && w.sMin > 0)) throw Error("--smin", "expected a finite slope > 0, got " + num(w.sMin));
    if (!(std::isfinite(w.sMax) && w.sMax > w.sMin))
        throw Error("--smax", "expected a finite slope > s_min = " + num(w.sMin) + ", got " + num(w.sMax));
    if (!(std::isfinite(w.omegaYMax) && w.omegaYMax > 0))
        throw Error("Omega_y^max", "expected a positive bandwidth");
}

double wedgeArea(const DoubleWedge& w) { return w.omegaYMax * w.omegaYMax * (1.0 / w.sMin - 1.0 / w.sMax); }

FourierFilter::FourierFilter(FilterKind kind, FilterShape shape, int components, const DoubleWedge& wedge,
                             const GaussianConvention& conv)
    : m_kind(kind), m_shape(shape), m_components(components), m_wedge(wedge), m_conv(conv) {
    validateWedge(wedge);
    if (!(conv.sigmaScale > 0 && std::isfinite(conv.sigmaScale)))
        throw Error("Gaussian convention", "sigma scale must be positive");
    const double om = wedge.omegaYMax;
    const double gScale = shape == FilterShape::Gaussian ? conv.sigmaScale : 1.0;
    switch (kind) {
    case FilterKind::Aaf:
        if (components != 1) throw Error("--components", "AAF has exactly 1 component");
        m_sx = gScale * om / wedge.sMin;  // eq. 2
        m_sy = gScale * om;
        break;
    case FilterKind::Fsf: {
        if (components != 1) throw Error("--components", "FSF has exactly 1 component");
        m_invSAvg = 0.5 * (1.0 / wedge.sMin + 1.0 / wedge.sMax);  // 1 / harmonic mean
        double halfWidth = 0.5 * om * (1.0 / wedge.sMin - 1.0 / wedge.sMax);  // tight parallelogram
        if (shape == FilterShape::Gaussian && conv.fsfSigmaAsPrinted)
            m_sx = gScale * 2.0 * halfWidth;  // eq. 4 as printed: Omega (1/s_min - 1/s_max)
        else
            m_sx = gScale * halfWidth;
        m_sy = gScale * om;
        break;
    }
    case FilterKind::Maaf: {
        if (components < 1 || components % 2 == 0 || components > 100001)
            throw Error("--components", "MAAF needs an odd number K = 2N - 1 >= 1 of filters, got " +
                                            std::to_string(components));
        filter::WedgeShape ws;
        ws.omegaYMax = om;
        ws.sMin = wedge.sMin;
        ws.sMax = wedge.sMax;
        m_comps = filter::maafComponents((components + 1) / 2, ws);  // eqs. 6-8, 10
        for (auto& c : m_comps) {
            c.sx *= gScale;
            c.sy *= gScale;
            if (shape == FilterShape::Gaussian && !conv.maafWeights) c.mu = 1;
        }
        break;
    }
    }
}

double FourierFilter::operator()(double wx, double wy) const {
    const bool box = m_shape == FilterShape::Box;
    switch (m_kind) {
    case FilterKind::Aaf:
        if (box) return (std::abs(wx) <= m_sx && std::abs(wy) <= m_sy) ? 1.0 : 0.0;
        return filter::fourierGaussian(wx, m_sx) * filter::fourierGaussian(wy, m_sy);  // eq. 2
    case FilterKind::Fsf: {
        double u = wx - wy * m_invSAvg;  // the shear of eq. 4
        if (box) return (std::abs(u) <= m_sx && std::abs(wy) <= m_sy) ? 1.0 : 0.0;
        return filter::fourierGaussian(u, m_sx) * filter::fourierGaussian(wy, m_sy);
    }
    case FilterKind::Maaf: return filter::maafSpectrum(m_comps, wx, wy, box);  // eq. 9
    }
    return 0;
}

void FourierFilter::nearbyComponents(double wy, std::vector<filter::MaafComponent>& out) const {
    out.clear();
    const double cut = m_shape == FilterShape::Box ? 1.0 : kCut;
    for (const auto& c : m_comps)
        if (std::abs(wy - c.cy) <= cut * c.sy || std::abs(wy + c.cy) <= cut * c.sy) out.push_back(c);
}

void FourierFilter::evalRow(double wy, const std::vector<double>& wxs, std::vector<double>& out) const {
    out.resize(wxs.size());
    if (m_kind != FilterKind::Maaf) {
        for (size_t i = 0; i < wxs.size(); ++i) out[i] = (*this)(wxs[i], wy);
        return;
    }
    // A component (with its mirror) far from this row contributes nothing: evaluate eq. 9 over
    // the nearby ones only, still through the shared maafSpectrum.
    thread_local std::vector<filter::MaafComponent> near;
    nearbyComponents(wy, near);
    for (size_t i = 0; i < wxs.size(); ++i) out[i] = filter::maafSpectrum(near, wxs[i], wy, m_shape == FilterShape::Box);
}

namespace {
/// The integral of G(w - c; sigma) over [a, b].
double gaussianIntegral(double a, double b, double c, double sigma) {
    const double k = 1.0 / (sigma * std::sqrt(2.0));
    return sigma * std::sqrt(M_PI / 2) * (std::erf((b - c) * k) - std::erf((a - c) * k));
}
double overlap(double a, double b, double lo, double hi) { return std::max(0.0, std::min(b, hi) - std::max(a, lo)); }
}  // namespace

double FourierFilter::rowIntegral(double wy, double a, double b) const {
    const bool box = m_shape == FilterShape::Box;
    if (m_kind != FilterKind::Maaf) {
        double c = m_kind == FilterKind::Fsf ? wy * m_invSAvg : 0.0;
        if (box) return std::abs(wy) <= m_sy ? overlap(a, b, c - m_sx, c + m_sx) : 0.0;
        return filter::fourierGaussian(wy, m_sy) * gaussianIntegral(a, b, c, m_sx);
    }
    double sum = 0;
    for (const auto& comp : m_comps)
        for (double sign : {1.0, -1.0}) {
            if (comp.p == 0 && sign < 0) continue;
            double dy = wy - sign * comp.cy, cx = sign * comp.cx;
            if (box) sum += std::abs(dy) <= comp.sy ? overlap(a, b, cx - comp.sx, cx + comp.sx) : 0.0;
            else if (std::abs(dy) <= kCut * comp.sy)
                sum += comp.mu * filter::fourierGaussian(dy, comp.sy) * gaussianIntegral(a, b, cx, comp.sx);
        }
    return sum;
}

double FourierFilter::integral() const {
    const bool box = m_shape == FilterShape::Box;
    if (m_kind != FilterKind::Maaf) return box ? 4.0 * m_sx * m_sy : kTwoPi * m_sx * m_sy;  // shear keeps area
    double sum = 0;
    for (const auto& c : m_comps) {
        double one = box ? 4.0 * c.sx * c.sy : c.mu * kTwoPi * c.sx * c.sy;
        sum += c.p == 0 ? one : 2.0 * one;  // p and its mirror -p
    }
    return sum;
}

std::vector<double> FourierFilter::yBreaks() const {
    std::vector<double> b{0.0};
    if (m_kind != FilterKind::Maaf) {
        b.push_back(m_sy);
        b.push_back(-m_sy);
    } else {
        for (const auto& c : m_comps)
            for (double e : {c.cy - c.sy, c.cy + c.sy}) {
                b.push_back(e);
                b.push_back(-e);
            }
    }
    std::sort(b.begin(), b.end());
    b.erase(std::unique(b.begin(), b.end()), b.end());
    return b;
}

void FourierFilter::rowBreaks(double wy, std::vector<double>& out) const {
    out.clear();
    if (m_shape != FilterShape::Box) return;
    switch (m_kind) {
    case FilterKind::Aaf: out = {-m_sx, m_sx}; break;
    case FilterKind::Fsf: out = {wy * m_invSAvg - m_sx, wy * m_invSAvg + m_sx}; break;
    case FilterKind::Maaf:
        for (const auto& c : m_comps)
            for (double sign : {1.0, -1.0}) {
                if (c.p == 0 && sign < 0) continue;
                if (std::abs(wy - sign * c.cy) > c.sy) continue;
                out.push_back(sign * c.cx - c.sx);
                out.push_back(sign * c.cx + c.sx);
            }
        break;
    }
}

double FourierFilter::extentX() const {
    const double cut = m_shape == FilterShape::Box ? 1.0 : kCut;
    if (m_kind == FilterKind::Aaf) return cut * m_sx;
    if (m_kind == FilterKind::Fsf) return cut * m_sx + extentY() * m_invSAvg;
    double e = 0;
    for (const auto& c : m_comps) e = std::max(e, std::abs(c.cx) + cut * c.sx);
    return e;
}

double FourierFilter::extentY() const {
    const double cut = m_shape == FilterShape::Box ? 1.0 : kCut;
    if (m_kind != FilterKind::Maaf) return cut * m_sy;
    double e = 0;
    for (const auto& c : m_comps) e = std::max(e, std::abs(c.cy) + cut * c.sy);
    return e;
}

}  // namespace wedge::analysis
