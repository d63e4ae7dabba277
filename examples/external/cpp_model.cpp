// An external model for vesselverify in C++ with the standard library only: it uses nothing of
// the project but the exchange format (manifest.json and problem.vtu of one case; see
// verification/exchange.schema.json), which it parses minimally itself.
//
// The model: a linear spring network on the tetrahedra's edges with Lloyd, Székely & Harders
// (2007)'s closed form used per element, k = (24/25)·E·Σ V_tet / L² (the sum over the tets sharing
// the edge), linearised at rest (K = Σ k n nᵀ), solved by Jacobi-preconditioned conjugate gradients
// with the fixed components held at zero. Writes displacements.csv (node,ux,uy,uz in m) and
// timing.json (its own set-up and solve time) beside the manifest.
//
// Usage: cpp_model CASE_DIR/manifest.json   (vesselverify appends the manifest's path)
// Static problems on tetra cells only: anything else is refused with exit code 2.
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using Vec = std::array<double, 3>;

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  if (!in) throw std::runtime_error(p.string() + ": cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The text after `"key":` in a JSON document (enough for this manifest's unique keys).
std::string json_value(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\"");
  if (at == std::string::npos) throw std::runtime_error("manifest: no key " + key);
  auto v = json.find(':', at) + 1;
  while (json[v] == ' ') ++v;
  const auto end = json.find_first_of(",}\n", v);
  return json.substr(v, end - v);
}

/// The numbers of the DataArray whose opening tag contains `marker` (its Name, or the first
/// DataArray after "<Points>").
std::vector<double> data_array(const std::string& vtu, const std::string& marker) {
  auto at = vtu.find(marker);
  if (at == std::string::npos) throw std::runtime_error("problem.vtu: no " + marker);
  if (marker == "<Points>") at = vtu.find("<DataArray", at);
  at = vtu.find('>', at) + 1;  // the end of the DataArray's opening tag
  const auto end = vtu.find("</DataArray>", at);
  std::istringstream s(vtu.substr(at, end - at));
  std::vector<double> v;
  double x = 0.0;
  while (s >> x) v.push_back(x);
  return v;
}

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

struct Spring {
  int a, b;
  double k;
  Vec n;  ///< unit direction a → b at rest
};

/// One case's static problem, as the manifest and problem.vtu give it.
struct Case {
  std::filesystem::path dir;  ///< the manifest's folder, where the answer goes
  double E = 0.0;             ///< Young's modulus, Pa
  std::vector<double> xyz, conn, load, fixed;
  std::size_t n = 0;  ///< points
};

/// The case of a manifest, or nothing (with the reason on stderr) if this model does not
/// answer it: another schema, a dynamic problem, cells other than tetra, mismatched arrays.
std::optional<Case> read_case(const std::filesystem::path& manifest_path) {
  Case c;
  c.dir = std::filesystem::absolute(manifest_path).parent_path();
  const std::string manifest = read_text(manifest_path);
  if (json_value(manifest, "schema").find("vesselverify.exchange") == std::string::npos) {
    std::cerr << "expected a vesselverify.exchange manifest\n";
    return std::nullopt;
  }
  if (json_value(manifest, "type").find("static") == std::string::npos) {
    std::cerr << "this example answers static problems only\n";
    return std::nullopt;
  }
  if (json_value(manifest, "cell_type").find("tetra") == std::string::npos) {
    std::cerr << "this example needs tetra cells (nodes = \"volume\")\n";
    return std::nullopt;
  }
  c.E = std::stod(json_value(manifest, "youngs_modulus_pa"));
  const std::string vtu = read_text(c.dir / "problem.vtu");
  c.xyz = data_array(vtu, "<Points>");
  c.conn = data_array(vtu, "Name=\"connectivity\"");
  c.load = data_array(vtu, "Name=\"load_N\"");
  c.fixed = data_array(vtu, "Name=\"fixed\"");
  c.n = c.xyz.size() / 3;
  if (c.load.size() != 3 * c.n || c.fixed.size() != 3 * c.n || c.conn.size() % 4 != 0) {
    std::cerr << "problem.vtu: array sizes do not match " << c.n << " points\n";
    return std::nullopt;
  }
  return c;
}

/// One spring per tetrahedron edge: Σ V_tet per edge, then k = (24/25)·E·ΣV/L² (Lloyd et al.
/// 2007, per element).
std::vector<Spring> edge_springs(const Case& c) {
  const auto point = [&](std::size_t i) {
    return Vec{c.xyz[3 * i], c.xyz[3 * i + 1], c.xyz[3 * i + 2]};
  };
  std::map<std::pair<int, int>, double> volume_around;
  constexpr int kPairs[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (std::size_t t = 0; t < c.conn.size(); t += 4) {
    int v[4];
    for (int i = 0; i < 4; ++i) v[i] = static_cast<int>(c.conn[t + i]);
    const Vec x0 = point(v[0]);
    const double V =
        std::abs(dot(cross(sub(point(v[1]), x0), sub(point(v[2]), x0)), sub(point(v[3]), x0))) / 6.0;
    for (const auto& p : kPairs) {
      const int a = std::min(v[p[0]], v[p[1]]), b = std::max(v[p[0]], v[p[1]]);
      volume_around[{a, b}] += V;
    }
  }
  std::vector<Spring> springs;
  for (const auto& [edge, V] : volume_around) {
    const Vec d = sub(point(edge.second), point(edge.first));
    const double L = std::sqrt(dot(d, d));
    springs.push_back({edge.first, edge.second, 24.0 / 25.0 * c.E * V / (L * L),
                       {d[0] / L, d[1] / L, d[2] / L}});
  }
  return springs;
}

/// The displacements from conjugate gradients, or nothing if they did not converge.
struct CgSolution {
  std::vector<double> u;
  long iterations = 0;
  bool converged = true;
};

/// Conjugate gradients on K u = f (K = Σ k n nᵀ), Jacobi preconditioner, fixed components zero;
/// stops at ‖r‖ ≤ 1e-10 ‖f‖, fails after 20 × (unknowns) iterations.
CgSolution solve_cg(const std::vector<Spring>& springs, const Case& c) {
  const std::vector<double>& fixed = c.fixed;
  const std::size_t m = 3 * c.n;
  const auto apply = [&](const std::vector<double>& u, std::vector<double>& out) {
    std::fill(out.begin(), out.end(), 0.0);
    for (const Spring& s : springs) {
      double stretch = 0.0;
      for (int j = 0; j < 3; ++j) stretch += s.n[j] * (u[3 * s.b + j] - u[3 * s.a + j]);
      for (int j = 0; j < 3; ++j) {
        out[3 * s.b + j] += s.k * stretch * s.n[j];
        out[3 * s.a + j] -= s.k * stretch * s.n[j];
      }
    }
    for (std::size_t i = 0; i < m; ++i) {
      if (fixed[i] != 0.0) out[i] = 0.0;
    }
  };
  std::vector<double> diagonal(m, 0.0);
  for (const Spring& s : springs) {
    for (int j = 0; j < 3; ++j) {
      diagonal[3 * s.a + j] += s.k * s.n[j] * s.n[j];
      diagonal[3 * s.b + j] += s.k * s.n[j] * s.n[j];
    }
  }
  CgSolution out;
  std::vector<double>& u = out.u;
  u.assign(m, 0.0);
  std::vector<double> r(m), z(m), p(m), q(m);
  double norm_f = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    r[i] = fixed[i] != 0.0 ? 0.0 : c.load[i];
    norm_f += r[i] * r[i];
  }
  norm_f = std::sqrt(norm_f);
  const auto precondition = [&] {
    for (std::size_t i = 0; i < m; ++i) z[i] = fixed[i] != 0.0 ? 0.0 : r[i] / diagonal[i];
  };
  precondition();
  p = z;
  double rz = 0.0;
  for (std::size_t i = 0; i < m; ++i) rz += r[i] * z[i];
  while (norm_f > 0.0) {
    apply(p, q);
    double pq = 0.0;
    for (std::size_t i = 0; i < m; ++i) pq += p[i] * q[i];
    const double alpha = rz / pq;
    double norm_r = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      u[i] += alpha * p[i];
      r[i] -= alpha * q[i];
      norm_r += r[i] * r[i];
    }
    ++out.iterations;
    if (std::sqrt(norm_r) <= 1e-10 * norm_f) break;
    if (out.iterations > 20 * static_cast<long>(m)) {
      std::cerr << "conjugate gradients did not converge in " << out.iterations
                << " iterations\n";
      out.converged = false;
      return out;
    }
    precondition();
    double rz_new = 0.0;
    for (std::size_t i = 0; i < m; ++i) rz_new += r[i] * z[i];
    for (std::size_t i = 0; i < m; ++i) p[i] = z[i] + rz_new / rz * p[i];
    rz = rz_new;
  }
  return out;
}

/// displacements.csv (node,ux,uy,uz in m), written under a temporary name and renamed: never
/// half a file.
void write_displacements(const std::filesystem::path& dir, const std::vector<double>& u,
                         std::size_t n) {
  {
    std::ofstream out(dir / "displacements.csv.tmp");
    out.precision(17);
    out << "node,ux,uy,uz\n";
    for (std::size_t i = 0; i < n; ++i) {
      out << i << ',' << u[3 * i] << ',' << u[3 * i + 1] << ',' << u[3 * i + 2] << '\n';
    }
  }
  std::filesystem::rename(dir / "displacements.csv.tmp", dir / "displacements.csv");
}

int run(const std::filesystem::path& manifest_path) {
  const auto start = std::chrono::steady_clock::now();
  const std::optional<Case> c = read_case(manifest_path);
  if (!c) return 2;
  const std::vector<Spring> springs = edge_springs(*c);
  const auto set_up = std::chrono::steady_clock::now();
  const CgSolution solution = solve_cg(springs, *c);
  if (!solution.converged) return 1;
  const auto solved = std::chrono::steady_clock::now();
  write_displacements(c->dir, solution.u, c->n);
  {
    const auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
    std::ofstream out(c->dir / "timing.json");
    out.precision(9);
    out << "{\"setup_seconds\": " << seconds(start, set_up)
        << ", \"solve_seconds\": " << seconds(set_up, solved) << "}\n";
  }
  std::cout << c->n << " nodes, " << springs.size() << " springs, CG " << solution.iterations
            << " iterations\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const char* manifest = argc > 1 ? argv[1] : std::getenv("VESSELVERIFY_MANIFEST");
  if (!manifest) {
    std::cerr << "usage: cpp_model CASE_DIR/manifest.json\n";
    return 2;
  }
  try {
    return run(manifest);
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
}
