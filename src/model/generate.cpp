// generate_mobile(): a random balanced mobile as mobile-file text.
//
// Shape of the result: a fixed hook (a small sphere) carries one top bar; bars form a binary tree; leaves
// are plates (regular polygons of 5 to 8 sides in a vertical plane) or balls. Every component hangs from a
// thin vertical thread whose top is its joint, so a leaf's centre of mass lies exactly under its joint.
// When the component count forces it (an even number of moving components), exactly one bar carries a
// single leaf at one end, with its pivot between the bar's own centre of mass and the leaf.
//
// Layout (bottom-up, linear time): every subtree has a footprint, an axis-aligned rectangle in the
// horizontal x-z plane relative to its joint. Bars alternate between the x and z directions (an H-tree),
// and a bar is just long enough for its two children's footprints to be separated by a gap, so bar lengths
// grow like the square root of the number of leaves and no two subtrees can touch.
//
// Balance: mode "mass" (compile() scales the masses). The generator repeats compile()'s per-bar
// computation (scale factors closest to all-ones that balance the bar, balance.cpp) along the bar's line
// with the base (steel) masses; each pivot sits a little off the point where the base masses balance, and
// moves onto it when a factor would leave [kMinFactor, 1/kMinFactor], so the derived masses stay close to
// the steel ones however deep the tree.
//
// Determinism: std::mt19937 with our own mapping to numbers, and every coordinate an integer number of
// micrometres, printed exactly; so the same options give the same text with any compiler and library.

#include "aloft/generate.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace aloft {

namespace {

using Micro = std::int64_t;  // micrometres

constexpr double kPi = std::numbers::pi;
constexpr double kDensity = 7850;         // steel, the format's default
constexpr Micro kThreadRadius = 500;      // 0.5 mm
constexpr Micro kPlateThickness = 2000;   // 2 mm
constexpr Micro kHookRadius = 10000;      // 1 cm
constexpr double kMinFactor = 0.8;        // balance factors of the base design stay in [0.8, 1.25]

class Random {
 public:
  explicit Random(unsigned seed) : engine_(seed) {}
  // Uniform in [0, 1), 53 bits.
  double unit() {
    const std::uint64_t a = engine_() >> 5, b = engine_() >> 6;
    return static_cast<double>(a * 67108864ull + b) / 9007199254740992.0;
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  // Uniform multiple of 0.1 mm in [lo, hi] (micrometres, multiples of 100).
  Micro length(Micro lo, Micro hi) { return 100 * integer(lo / 100, hi / 100); }
  // Uniform integer in [lo, hi].
  Micro integer(Micro lo, Micro hi) {
    const std::uint64_t span = static_cast<std::uint64_t>(hi - lo) + 1;
    return lo + static_cast<Micro>(static_cast<std::uint64_t>(unit() * static_cast<double>(span)) % span);
  }
  bool coin() { return (engine_() >> 31) != 0; }

 private:
  std::mt19937 engine_;
};

struct Rect {  // footprint relative to the joint, micrometres
  Micro x0 = 0, x1 = 0, z0 = 0, z1 = 0;
};

enum class Kind { Bar, Plate, Ball };

struct Node {
  Kind kind = Kind::Ball;
  int child[2] = {-1, -1};       // bar: children (child[1] == -1: a single child at the + end)
  int axis = 0;                  // bar: 0 = along x, 1 = along z
  Micro thread = 0;              // thread length below the joint
  // Bar: ends relative to the pivot along the axis (minus < 0 < plus); radius of the bar wire.
  Micro minus = 0, plus = 0, bar_radius = 0;
  // Leaf: circumradius (plate) or radius (ball); plate sides and horizontal in-plane direction.
  Micro size = 0;
  int sides = 0;
  Micro ux = 0, uz = 0;
  std::uint32_t color = 0;
  // Derived.
  Rect rect;
  Micro depth = 0;               // how far the subtree reaches below its joint
  double base_mass = 0;          // own mass at steel density, kg
  double sub_mass = 0;           // balanced subtree mass at this component's own scale, kg
  // Placement (pass 2): the joint, world.
  Micro jx = 0, jy = 0, jz = 0;
  int parent = -1;
  int number = 0;                // for the name
};

double wire_mass(Micro radius, Micro length) {
  const double r = radius * 1e-6, l = length * 1e-6;
  return kDensity * kPi * r * r * l;
}

// Compile()'s balance factors for masses m[k] at signed lever arms a[k] along one line:
// x = 1 - b (sum b) / |b|^2 with b[k] = m[k] a[k]; returns the smallest.
double smallest_factor(const double* m, const double* a, int k, double* x) {
  double sum = 0, norm2 = 0;
  double b[3];
  for (int i = 0; i < k; ++i) {
    b[i] = std::abs(a[i]) < 1e-6 ? 0 : m[i] * a[i];
    sum += b[i];
    norm2 += b[i] * b[i];
  }
  double smallest = 1;
  for (int i = 0; i < k; ++i) {
    x[i] = norm2 > 0 ? 1 - b[i] * sum / norm2 : 1;
    smallest = std::min(smallest, x[i]);
  }
  return smallest;
}

class Generator {
 public:
  Generator(const GenerateOptions& options) : options_(options), random_(options.seed) {}

  std::string run() {
    if (options_.components < 2)
      throw std::invalid_argument("generate_mobile: a mobile needs at least 2 components (the hook and one more)");
    if (!(options_.total_mass > 0) || !std::isfinite(options_.total_mass))
      throw std::invalid_argument("generate_mobile: total_mass must be a positive number");
    nodes_.reserve(static_cast<std::size_t>(options_.components));
    const int top = build(options_.components - 1, random_.coin() ? 0 : 1);
    place(top);
    return print();
  }

 private:
  // Builds (and lays out) a subtree of `count` components, bottom-up; returns its index.
  int build(int count, int axis) {
    if (count == 1) return leaf();
    if (count == 2) return single_bar(leaf(), axis);
    // Split count - 1 between two children: both odd when count is odd, one odd and one even otherwise.
    const int rest = count - 1;
    int first = static_cast<int>(std::lround(rest * random_.uniform(0.35, 0.65)));
    first = std::clamp(first, 1, rest - 1);
    if (rest % 2 == 0 && first % 2 == 0) first += (first + 1 <= rest - 1) ? 1 : -1;
    const int a = build(first, 1 - axis);
    const int b = build(rest - first, 1 - axis);
    return random_.coin() ? double_bar(a, b, axis) : double_bar(b, a, axis);
  }

  std::uint32_t random_color(bool bar) {
    if (bar) {  // dark, slightly tinted
      const auto c = [&] { return static_cast<std::uint32_t>(random_.integer(0x18, 0x48)); };
      return c() << 16 | c() << 8 | c();
    }
    // A saturated colour: hue at random, one channel high, one low.
    const double h = random_.unit() * 6, s = random_.uniform(0.55, 0.9), v = random_.uniform(0.7, 0.95);
    const int sector = std::min(static_cast<int>(h), 5);
    const double f = h - sector, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    double r = v, g = t, b = p;
    switch (sector) {
      case 0: r = v, g = t, b = p; break;
      case 1: r = q, g = v, b = p; break;
      case 2: r = p, g = v, b = t; break;
      case 3: r = p, g = q, b = v; break;
      case 4: r = t, g = p, b = v; break;
      default: r = v, g = p, b = q; break;
    }
    const auto byte = [](double c) { return static_cast<std::uint32_t>(std::clamp(std::lround(c * 255), 0l, 255l)); };
    return byte(r) << 16 | byte(g) << 8 | byte(b);
  }

  int leaf() {
    Node n;
    n.kind = random_.unit() < 0.75 ? Kind::Plate : Kind::Ball;
    n.thread = random_.length(30000, 80000);
    if (n.kind == Kind::Plate) {
      n.sides = static_cast<int>(random_.integer(5, 8));
      n.size = random_.length(25000, 50000);
      // Horizontal direction of the plate's plane (need not be unit: the parser normalises it).
      const double angle = random_.unit() * kPi;
      n.ux = 1000 * std::llround(std::cos(angle) * 1000);
      n.uz = 1000 * std::llround(std::sin(angle) * 1000);
      const double r = n.size * 1e-6;
      const double area = 0.5 * n.sides * r * r * std::sin(2 * kPi / n.sides);
      n.base_mass = kDensity * area * kPlateThickness * 1e-6 + wire_mass(kThreadRadius, n.thread);
      const Micro half = n.size + kPlateThickness;
      n.rect = {-half, half, -half, half};
      n.depth = n.thread + 2 * n.size;
    } else {
      n.size = random_.length(15000, 35000);
      const double r = n.size * 1e-6;
      n.base_mass = kDensity * 4.0 / 3.0 * kPi * r * r * r + wire_mass(kThreadRadius, n.thread);
      n.rect = {-n.size, n.size, -n.size, n.size};
      n.depth = n.thread + 2 * n.size;
    }
    n.sub_mass = n.base_mass;
    n.color = random_color(false);
    nodes_.push_back(n);
    return static_cast<int>(nodes_.size()) - 1;
  }

  // Footprint of child c along (lo, hi) and across (cross_lo, cross_hi) a bar on `axis`.
  static void extents(const Rect& r, int axis, Micro& lo, Micro& hi, Micro& cross_lo, Micro& cross_hi) {
    if (axis == 0) {
      lo = r.x0, hi = r.x1, cross_lo = r.z0, cross_hi = r.z1;
    } else {
      lo = r.z0, hi = r.z1, cross_lo = r.x0, cross_hi = r.x1;
    }
  }

  static Rect make_rect(int axis, Micro lo, Micro hi, Micro cross_lo, Micro cross_hi) {
    return axis == 0 ? Rect{lo, hi, cross_lo, cross_hi} : Rect{cross_lo, cross_hi, lo, hi};
  }

  static Micro bar_radius_for(Micro length) {
    // About 1 mm for a 20 cm bar, thicker for long bars (radius ~ sqrt(length)), 0.8..8 mm.
    const double r = 10.0 * std::sqrt(static_cast<double>(length) / 200000.0);
    return 100 * std::clamp<Micro>(std::llround(r), 8, 80);
  }

  int double_bar(int a, int b, int axis) {
    Node n;
    n.kind = Kind::Bar;
    n.axis = axis;
    n.child[0] = a;  // at the minus end
    n.child[1] = b;  // at the plus end
    n.thread = random_.length(20000, 60000);
    Micro alo, ahi, acl, ach, blo, bhi, bcl, bch;
    extents(nodes_[a].rect, axis, alo, ahi, acl, ach);
    extents(nodes_[b].rect, axis, blo, bhi, bcl, bch);
    const Micro gap = random_.length(20000, 50000);
    const Micro length = std::max<Micro>(ahi - blo + gap, 60000);
    n.bar_radius = bar_radius_for(length);
    const double mt = wire_mass(kThreadRadius, n.thread), mw = wire_mass(n.bar_radius, length);
    const double sa = nodes_[a].sub_mass, sb = nodes_[b].sub_mass;
    const double l = length * 1e-6;
    // Factors for a pivot at fraction f from the minus end.
    auto factors = [&](double f, double* x) {
      const double m[3] = {mt + mw, sa, sb};
      const double arm[3] = {mw * (0.5 - f) * l / (mt + mw), -f * l, (1 - f) * l};
      return smallest_factor(m, arm, 3, x);
    };
    // The pivot lies near where the base masses balance, a little off at random, so that compile()'s
    // factors stay near 1: they multiply down the tree, and factors far from 1 at every level would give
    // a deep mobile pieces of absurdly different weights (and spin its lightest ones at hundreds of rad/s).
    const double balanced = (0.5 * mw + sb) / (mw + sa + sb);
    double f = std::clamp(balanced + random_.uniform(-0.03, 0.03), 0.1, 0.9);
    double x[3];
    factors(f, x);
    if (std::min({x[0], x[1], x[2]}) < kMinFactor || std::max({x[0], x[1], x[2]}) > 1 / kMinFactor) f = balanced;
    n.minus = -100 * std::llround(f * static_cast<double>(length) / 100);
    n.plus = length + n.minus;
    // The sub-mass as compile() computes it, with the factors of the pivot actually written.
    const double fw = static_cast<double>(-n.minus) / static_cast<double>(length);
    factors(fw, x);
    n.base_mass = mt + mw;
    n.sub_mass = x[0] * n.base_mass + x[1] * sa + x[2] * sb;
    n.rect = make_rect(axis, n.minus + alo, n.plus + bhi, std::min<Micro>({acl, bcl, -n.bar_radius}),
                       std::max<Micro>({ach, bch, n.bar_radius}));
    n.depth = n.thread + std::max(nodes_[a].depth, nodes_[b].depth);
    n.color = random_color(true);
    nodes_.push_back(n);
    return static_cast<int>(nodes_.size()) - 1;
  }

  // A bar carrying one child at its plus end; the pivot lies between the bar's centre and the child, where
  // the bar's own weight balances the child's (at base masses; compile() makes it exact).
  int single_bar(int c, int axis) {
    Node n;
    n.kind = Kind::Bar;
    n.axis = axis;
    n.child[0] = c;
    n.child[1] = -1;
    n.thread = random_.length(20000, 50000);
    const Micro length = random_.length(100000, 180000);
    n.bar_radius = bar_radius_for(length) + 700;  // a little heavier: it balances a leaf
    const double mt = wire_mass(kThreadRadius, n.thread), mw = wire_mass(n.bar_radius, length);
    const double sc = nodes_[c].sub_mass;
    // mw (0.5 - f) + sc (1 - f) = 0 about the pivot at fraction f from the minus end.
    const double f = std::clamp((0.5 * mw + sc) / (mw + sc), 0.55, 0.95);
    n.minus = -100 * std::llround(f * static_cast<double>(length) / 100);
    n.plus = length + n.minus;
    const double fw = static_cast<double>(-n.minus) / static_cast<double>(length);
    const double m[2] = {mt + mw, sc};
    const double arm[2] = {mw * (0.5 - fw) * length * 1e-6 / (mt + mw), (1 - fw) * length * 1e-6};
    double x[2];
    smallest_factor(m, arm, 2, x);
    n.base_mass = mt + mw;
    n.sub_mass = x[0] * n.base_mass + x[1] * sc;
    Micro lo, hi, cl, ch;
    extents(nodes_[c].rect, axis, lo, hi, cl, ch);
    n.rect = make_rect(axis, std::min(n.minus - n.bar_radius, n.plus + lo), n.plus + hi,
                       std::min(cl, -n.bar_radius), std::max(ch, n.bar_radius));
    n.depth = n.thread + nodes_[c].depth;
    n.color = random_color(true);
    nodes_.push_back(n);
    return static_cast<int>(nodes_.size()) - 1;
  }

  // Pass 2: world joints, top-down (explicit stack), names numbered in file (preorder) order.
  void place(int top) {
    hook_y_ = std::max<Micro>(2000000, nodes_[top].depth + kHookRadius + 300000);
    Node& t = nodes_[top];
    t.jx = 0, t.jy = hook_y_ - kHookRadius, t.jz = 0;
    order_.clear();
    std::vector<int> stack{top};
    int bars = 0, leaves = 0;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      order_.push_back(i);
      Node& n = nodes_[i];
      n.number = n.kind == Kind::Bar ? ++bars : ++leaves;
      if (n.kind != Kind::Bar) continue;
      const Micro y = n.jy - n.thread;
      for (int k = 1; k >= 0; --k) {
        const int c = n.child[k];
        if (c < 0) continue;
        const Micro along = (k == 0 && n.child[1] >= 0) ? n.minus : n.plus;
        Node& ch = nodes_[c];
        ch.parent = i;
        ch.jx = n.jx + (n.axis == 0 ? along : 0);
        ch.jz = n.jz + (n.axis == 1 ? along : 0);
        ch.jy = y;
        stack.push_back(c);
      }
    }
  }

  // ---- printing ----
  void number(Micro v) {  // micrometres as metres, exactly
    if (v < 0) {
      out_ += '-';
      v = -v;
    }
    out_ += std::to_string(v / 1000000);
    const Micro frac = v % 1000000;
    if (frac != 0) {
      char digits[8];
      std::snprintf(digits, sizeof digits, "%06lld", static_cast<long long>(frac));
      std::string s(digits);
      while (s.back() == '0') s.pop_back();
      out_ += '.';
      out_ += s;
    }
  }
  void point(Micro x, Micro y, Micro z) {
    out_ += '[';
    number(x);
    out_ += ", ";
    number(y);
    out_ += ", ";
    number(z);
    out_ += ']';
  }
  void wire(Micro x0, Micro y0, Micro z0, Micro x1, Micro y1, Micro z1, Micro r) {
    out_ += "{\"wire\": {\"from\": ";
    point(x0, y0, z0);
    out_ += ", \"to\": ";
    point(x1, y1, z1);
    out_ += ", \"radius\": ";
    number(r);
    out_ += "}}";
  }
  std::string name(int i) const {
    const Node& n = nodes_[i];
    const char* kind = n.kind == Kind::Bar ? "bar" : n.kind == Kind::Plate ? "plate" : "ball";
    return std::string(kind) + " " + std::to_string(n.number);
  }
  void color(std::uint32_t c) {
    char s[16];
    std::snprintf(s, sizeof s, "\"#%06x\"", static_cast<unsigned>(c));
    out_ += s;
  }

  std::string print() {
    out_.reserve(static_cast<std::size_t>(options_.components) * 400 + 1024);
    char mass[64];
    const auto res = std::to_chars(mass, mass + sizeof mass, options_.total_mass);
    out_ += "{\n  \"name\": \"random mobile (" + std::to_string(options_.components) + " components, seed " +
            std::to_string(options_.seed) + ")\",\n";
    out_ += "  \"aloft\": 1,\n";
    out_ += "  \"balance\": {\"mode\": \"mass\", \"total_mass\": " + std::string(mass, res.ptr) + "},\n";
    out_ += "  \"damping\": {\"linear\": 0.01, \"angular\": 0.02},\n";
    out_ += "  \"components\": [\n";
    out_ += "    {\"name\": \"hook\", \"fixed\": true, \"color\": \"#333333\",\n     \"shapes\": [{\"sphere\": {\"center\": ";
    point(0, hook_y_, 0);
    out_ += ", \"radius\": ";
    number(kHookRadius);
    out_ += "}}]}";
    for (int i : order_) {
      const Node& n = nodes_[i];
      out_ += ",\n    {\"name\": \"" + name(i) + "\", \"parent\": \"" + (n.parent < 0 ? std::string("hook") : name(n.parent)) +
              "\", \"joint\": ";
      point(n.jx, n.jy, n.jz);
      out_ += ", \"color\": ";
      color(n.color);
      out_ += ",\n     \"shapes\": [";
      const Micro y = n.jy - n.thread;
      wire(n.jx, n.jy, n.jz, n.jx, y, n.jz, kThreadRadius);
      out_ += ", ";
      if (n.kind == Kind::Bar) {
        const Micro dx = n.axis == 0 ? 1 : 0, dz = n.axis == 1 ? 1 : 0;
        wire(n.jx + dx * n.minus, y, n.jz + dz * n.minus, n.jx + dx * n.plus, y, n.jz + dz * n.plus, n.bar_radius);
      } else if (n.kind == Kind::Ball) {
        out_ += "{\"sphere\": {\"center\": ";
        point(n.jx, y - n.size, n.jz);
        out_ += ", \"radius\": ";
        number(n.size);
        out_ += "}}";
      } else {
        // A regular polygon in the vertical plane through the thread, a corner at the top touching it,
        // symmetric about the vertical so its centroid lies exactly under the joint.
        out_ += "{\"plate\": {\"plane\": {\"origin\": ";
        point(n.jx, y - n.size, n.jz);
        out_ += ", \"u\": ";
        point(n.ux, 0, n.uz);
        out_ += ", \"v\": [0, 1, 0]}, \"thickness\": ";
        number(kPlateThickness);
        out_ += ", \"points\": [";
        std::vector<Micro> a(n.sides), b(n.sides);
        for (int k = 0; k <= n.sides / 2; ++k) {
          const double angle = 2 * kPi * k / n.sides;
          a[k] = (k == 0 || 2 * k == n.sides) ? 0 : -100 * std::llround(std::sin(angle) * n.size / 100);
          b[k] = 100 * std::llround(std::cos(angle) * n.size / 100);
          if (k > 0) {
            a[n.sides - k] = -a[k];
            b[n.sides - k] = b[k];
          }
        }
        for (int k = 0; k < n.sides; ++k) {
          if (k) out_ += ", ";
          out_ += '[';
          number(a[k]);
          out_ += ", ";
          number(b[k]);
          out_ += ']';
        }
        out_ += "]}}";
      }
      out_ += "]}";
    }
    out_ += "\n  ]\n}\n";
    return std::move(out_);
  }

  GenerateOptions options_;
  Random random_;
  std::vector<Node> nodes_;
  std::vector<int> order_;
  Micro hook_y_ = 0;
  std::string out_;
};

}  // namespace

std::string generate_mobile(const GenerateOptions& options) { return Generator(options).run(); }

}  // namespace aloft
