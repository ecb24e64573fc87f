#include "core/volume/skip_distance.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace eikon {
namespace {

// The neighbour index along axis a (stride s) of a voxel at coordinate c on that axis, clamped.
inline size_t down(size_t idx, int c, size_t s) { return c > 0 ? idx - s : idx; }
inline size_t up(size_t idx, int c, int n, size_t s) { return c + 1 < n ? idx + s : idx; }

// Direct evaluation: the 26 neighbours of every voxel not yet active (fields holding NaN, for
// which min/max do not describe !=).
void markDirect(const std::vector<float>& f, const Grid& g, std::vector<uint8_t>& active,
                int threads) {
  parallelFor(g.dims[2], threads, [&](int k) {
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const size_t idx = g.index(i, j, k);
        for (int dz = -1; dz <= 1 && !active[idx]; ++dz)
          for (int dy = -1; dy <= 1 && !active[idx]; ++dy)
            for (int dx = -1; dx <= 1 && !active[idx]; ++dx) {
              const int x = std::clamp(i + dx, 0, g.dims[0] - 1),
                        y = std::clamp(j + dy, 0, g.dims[1] - 1),
                        z = std::clamp(k + dz, 0, g.dims[2] - 1);
              if (f[g.index(x, y, z)] != f[idx]) active[idx] = 1;
            }
      }
  });
}

// One axis of the separable 3×3×3 min and max: out = min/max of in over {c − 1, c, c + 1} along
// axis a, clamped at the faces (the clamped neighbour is the voxel itself).
void window3(const std::vector<float>& lo_in, const std::vector<float>& hi_in,
             std::vector<float>& lo_out, std::vector<float>& hi_out, const Grid& g, int a,
             int threads) {
  const size_t s = a == 0 ? 1 : a == 1 ? size_t(g.dims[0]) : size_t(g.dims[0]) * g.dims[1];
  const int n = g.dims[size_t(a)];
  parallelFor(g.dims[2], threads, [&](int k) {
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const size_t idx = g.index(i, j, k);
        const int c = a == 0 ? i : a == 1 ? j : k;
        const size_t d = down(idx, c, s), u = up(idx, c, n, s);
        lo_out[idx] = std::min(std::min(lo_in[d], lo_in[idx]), lo_in[u]);
        hi_out[idx] = std::max(std::max(hi_in[d], hi_in[idx]), hi_in[u]);
      }
  });
}

// Without NaN, != is "not equal" of a total order: a 3×3×3 block holds a value differing from
// its centre iff it is not uniform, iff its max differs from its min.
void markByMinMax(const std::vector<float>& f, const Grid& g, std::vector<uint8_t>& active,
                  int threads) {
  std::vector<float> lo = f, hi = f, lo2(f.size()), hi2(f.size());
  for (int a = 0; a < 3; ++a) {
    window3(lo, hi, lo2, hi2, g, a, threads);
    lo.swap(lo2);
    hi.swap(hi2);
  }
  parallelFor(g.dims[2], threads, [&](int k) {
    const size_t begin = g.index(0, 0, k), end = begin + size_t(g.dims[0]) * g.dims[1];
    for (size_t i = begin; i < end; ++i) active[i] |= uint8_t(hi[i] != lo[i]);
  });
}

// chebyshevLine with caller-owned scratch (s, t: n ints each).
void chebyshevLine(const int* f, int n, int* out, int* s, int* t) {
  // The cone of i, max(|x − i|, f[i]); sep(i, u) for i < u: the last x where the cone of i is
  // not above the cone of u (Meijster et al., Table 1, the L∞ column).
  auto cone = [f](int x, int i) { return std::max(std::abs(x - i), f[i]); };
  auto sep = [f](int i, int u) {
    return f[i] <= f[u] ? std::max(i + f[u], (i + u) / 2) : std::min(u - f[i], (i + u) / 2);
  };
  int q = 0;
  s[0] = 0;
  t[0] = 0;
  for (int u = 1; u < n; ++u) {
    while (q >= 0 && cone(t[q], s[q]) > cone(t[q], u)) --q;
    if (q < 0) {
      q = 0;
      s[0] = u;
    } else {
      const int w = 1 + sep(s[q], u);
      if (w < n) {
        ++q;
        s[q] = u;
        t[q] = w;
      }
    }
  }
  for (int u = n - 1; u >= 0; --u) {
    out[u] = cone(u, s[q]);
    if (u == t[q]) --q;
  }
}

}  // namespace

std::vector<uint8_t> activeVoxels(const std::vector<const std::vector<float>*>& fields,
                                  const Grid& g, int threads) {
  std::vector<uint8_t> active(g.count(), 0);
  for (const std::vector<float>* f : fields) {
    if (std::any_of(f->begin(), f->end(), [](float v) { return std::isnan(v); }))
      markDirect(*f, g, active, threads);
    else
      markByMinMax(*f, g, active, threads);
  }
  return active;
}

void chebyshevLine(const int* f, int n, int* g) {
  if (n <= 0) return;
  const size_t len = static_cast<size_t>(n);
  std::vector<int> s(len), t(len);
  chebyshevLine(f, n, g, s.data(), t.data());
}

void chebyshevTransform(std::vector<uint8_t>& dist, const Grid& g, int threads,
                        const std::function<void(int)>& after_axis) {
  for (int a = 0; a < 3; ++a) {
    const int n = g.dims[size_t(a)];
    const size_t stride = a == 0 ? 1 : a == 1 ? size_t(g.dims[0]) : size_t(g.dims[0]) * g.dims[1];
    // Lines along a, by the slab of the axis that is neither a nor x (x when a is x): z for a ∈
    // {x, y}, y for a = z. Each line is read into ints, transformed, written back.
    const int outer = a == 2 ? g.dims[1] : g.dims[2];
    const int inner = a == 0 ? g.dims[1] : g.dims[0];
    parallelFor(outer, threads, [&](int o) {
      const size_t len = static_cast<size_t>(n);
      std::vector<int> f(len), out(len), s(len), t(len);
      for (int in = 0; in < inner; ++in) {
        const size_t base = a == 0   ? g.index(0, in, o)
                            : a == 1 ? g.index(in, 0, o)
                                     : g.index(in, o, 0);
        for (int c = 0; c < n; ++c) f[size_t(c)] = dist[base + size_t(c) * stride];
        chebyshevLine(f.data(), n, out.data(), s.data(), t.data());
        for (int c = 0; c < n; ++c) dist[base + size_t(c) * stride] = uint8_t(out[size_t(c)]);
      }
    });
    if (after_axis) after_axis(a);
  }
}

}  // namespace eikon
