#include "app/fe_driver.hpp"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "base/bytes.hpp"
#include "base/collective_error.hpp"
#include "base/sorted_index.hpp"
#include "fem/fe_model.hpp"
#include "fem/shell.hpp"
#include "io/csv.hpp"
#include "io/fe_checkpoint.hpp"
#include "base/errors.hpp"
#include "io/run_info.hpp"
#include "io/h5_util.hpp"
#include "partition/mesh_distribute.hpp"
#include "partition/rendezvous.hpp"
#include "partition/mesh_partition.hpp"

namespace fdem {

namespace {

fem::ElemType element_type(const std::string& name) {
  fem::ElemType t;
  if (!fem::parse_element_type(name, t)) throw std::logic_error("unknown element type " + name);
  return t;
}

fem::FeMaterial to_material(const FeMaterialConfig& m) {
  fem::FeMaterial f;
  f.kind = m.mohr_coulomb ? fem::FeMaterial::kMohrCoulomb : fem::FeMaterial::kElastic;
  f.young = m.young;
  f.poisson = m.poisson;
  f.density = m.density;
  f.unit_weight = m.unit_weight;
  f.cohesion = m.cohesion;
  f.friction = m.friction_deg * M_PI / 180.0;
  f.dilation = m.dilation_deg * M_PI / 180.0;
  f.hourglass = m.hourglass;
  f.thickness = m.thickness;
  f.nlgeom = m.nlgeom;
  return f;
}

std::string set_names(const std::map<std::string, std::vector<std::int32_t>>& sets) {
  std::string s;
  for (const auto& kv : sets) s += (s.empty() ? "" : ", ") + kv.first;
  return s.empty() ? "none" : s;
}

using Resolved = FeBoundary;

std::vector<std::int32_t> node_set(const CaseConfig& c, const FeMeshes& m, const FeNodalConfig& b,
                                   const std::string& what) {
  const FeMeshes::Part& part = m.parts[b.mesh];
  if (b.has_region) {
    std::vector<std::int32_t> nodes;
    const int dim = part.mesh.dim;
    for (std::size_t i = 0; i < part.mesh.n_nodes(); ++i) {
      bool in = true;
      for (int d = 0; d < dim; ++d) {
        const double x = part.mesh.coords[i * dim + d];
        in = in && x >= b.region_min[d] && x <= b.region_max[d];
      }
      if (in) nodes.push_back(static_cast<std::int32_t>(i));
    }
    if (nodes.empty()) throw InputError(c.file, b.line, what + ": no node of mesh '" + part.name + "' lies in the region");
    return nodes;
  }
  auto it = part.mesh.node_sets.find(b.node_set);
  if (it == part.mesh.node_sets.end())
    throw InputError(c.file, b.line, what + ": mesh '" + part.name + "' has no node set '" + b.node_set +
                                         "' (valid: " + set_names(part.mesh.node_sets) + ")");
  if (it->second.empty()) throw InputError(c.file, b.line, what + ": node set '" + b.node_set + "' is empty");
  return it->second;
}

void resolve_restraints(const CaseConfig& c, const FeMeshes& m, Resolved& r) {
  const FeConfig& f = c.fem;
  for (std::size_t i = 0; i < f.restraints.size(); ++i) {
    const FeNodalConfig& b = f.restraints[i];
    const FeMeshes::Part& part = m.parts[b.mesh];
    Resolved::Group g;
    if (!b.file.empty()) {
      g.name = part.name + "_" + std::filesystem::path(b.file).stem().string();
      for (const fem::NodalRestraint& nr : fem::read_thesis_restraints(b.file, part.mesh)) {
        r.restraints.push_back({m.node(part, nr.node), nr.fixed, {0, 0, 0}});
        g.nodes.push_back(m.node(part, nr.node));
      }
    } else {
      g.name = part.name + "_" + (b.has_region ? "region" + std::to_string(i) : b.node_set);
      for (std::int32_t n : node_set(c, m, b, "fem.restraints[" + std::to_string(i) + "]")) {
        r.restraints.push_back({m.node(part, n), b.fixed, {0, 0, 0}, b.fixed_rot});
        g.nodes.push_back(m.node(part, n));
      }
    }
    r.reaction_groups.push_back(g);
  }
}

void resolve_displacements(const CaseConfig& c, const FeMeshes& m, Resolved& r) {
  const FeConfig& f = c.fem;
  for (std::size_t i = 0; i < f.displacements.size(); ++i) {
    const FeNodalConfig& b = f.displacements[i];
    const FeMeshes::Part& part = m.parts[b.mesh];
    Resolved::Group g;
    if (!b.file.empty()) {
      g.name = part.name + "_" + std::filesystem::path(b.file).stem().string();
      for (const fem::NodalVector& nv : fem::read_thesis_nodal_vectors(b.file, part.mesh)) {
        r.restraints.push_back({m.node(part, nv.node), {true, true, true}, nv.value});
        g.nodes.push_back(m.node(part, nv.node));
      }
    } else {
      g.name = part.name + "_" + (b.has_region ? "region_d" + std::to_string(i) : b.node_set);
      for (std::int32_t n : node_set(c, m, b, "fem.displacements[" + std::to_string(i) + "]")) {
        r.restraints.push_back({m.node(part, n), {true, true, true}, {b.value.x, b.value.y, b.value.z}});
        g.nodes.push_back(m.node(part, n));
      }
    }
    r.reaction_groups.push_back(g);
  }
}

/// fem.loads[i] as a pressure: p A n / 4 per node of every shell element (n: the element normal,
/// see fem/shell.hpp).
void resolve_pressure(const CaseConfig& c, const FeMeshes& m, std::size_t i, Resolved& r) {
  const FeNodalConfig& b = c.fem.loads[i];
  const FeMeshes::Part& part = m.parts[b.mesh];
  std::size_t shells = 0;
  for (std::size_t e = 0; e < part.mesh.n_elements(); ++e) {
    if (part.mesh.elem_type[e] != fem::ElemType::kShell4) continue;
    ++shells;
    const std::int32_t* nd;
    part.mesh.nodes_of(e, nd);
    double X[12];
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 3; ++d) X[3 * k + d] = part.mesh.coords[static_cast<std::size_t>(nd[k]) * 3 + d];
    double R[9];
    const double area = fem::shell4_frame(X, R, nullptr, nullptr, nullptr);
    const double F = b.pressure * area / 4;
    for (int k = 0; k < 4; ++k) r.loads.push_back({m.node(part, nd[k]), {F * R[6], F * R[7], F * R[8]}});
  }
  if (shells == 0)
    throw InputError(c.file, b.line, "fem.loads[" + std::to_string(i) + "]: a pressure needs shell4 elements; mesh '" +
                                         part.name + "' has none");
}

void resolve_loads(const CaseConfig& c, const FeMeshes& m, Resolved& r) {
  const FeConfig& f = c.fem;
  for (std::size_t i = 0; i < f.loads.size(); ++i) {
    const FeNodalConfig& b = f.loads[i];
    const FeMeshes::Part& part = m.parts[b.mesh];
    if (b.is_pressure) {
      resolve_pressure(c, m, i, r);
      continue;
    }
    if (!b.file.empty()) {
      for (const fem::NodalVector& nv : fem::read_thesis_nodal_vectors(b.file, part.mesh))
        r.loads.push_back({m.node(part, nv.node), nv.value});
    } else {
      const auto nodes = node_set(c, m, b, "fem.loads[" + std::to_string(i) + "]");
      const double s = 1.0 / static_cast<double>(nodes.size());
      for (std::int32_t n : nodes) r.loads.push_back({m.node(part, n), {b.value.x * s, b.value.y * s, b.value.z * s}});
    }
  }
}

Resolved resolve(const CaseConfig& c, const FeMeshes& m) {
  Resolved r;
  resolve_restraints(c, m, r);
  resolve_displacements(c, m, r);
  resolve_loads(c, m, r);
  for (const FeRemovalConfig& rm : c.fem.removals) {
    const FeMeshes::Part& part = m.parts[rm.mesh];
    if (!part.mesh.element_sets.count(rm.element_set))
      throw InputError(c.file, rm.line, "fem.remove: mesh '" + part.name + "' has no element set '" + rm.element_set +
                                            "' (valid: " + set_names(part.mesh.element_sets) + ")");
  }
  return r;
}

fem::FeMaterial material_of(const CaseConfig& c, int k) {
  fem::FeMaterial m = to_material(c.fem.materials[k]);
  m.density *= c.fem.mass_scaling;  // inertia only: the body load comes from unit_weight
  return m;
}

FeSnapshotData snapshot_data(const FeSetup& fe) {
  const fem::FeModel& model = *fe.model;
  const fem::Mesh& mesh = fe.mesh();
  FeSnapshotData d;
  const int dim = model.dim();
  d.dim = dim;
  d.n_nodes_global = fe.n_nodes;
  // Rows are the nodes' and elements' indices in the case's meshes (merged in the order of
  // fem.meshes: structures.json's node_offset / element_offset), not the solver's numbering.
  const auto& local = model.local_nodes();
  const std::vector<double> u = model.owned_displacements();
  const std::vector<double> v = model.owned_velocities();
  const std::vector<double>& fi = model.owned_interface_forces();  // n_owned x dofs per node
  const std::size_t nf = model.n_owned() > 0 ? fi.size() / model.n_owned() : 0;
  // A tied node (fem.ties) is no element's: its row repeats the node it became, which the
  // partition gives to the same rank.
  std::map<std::int32_t, std::size_t> owned_row;
  if (!mesh.tied_to.empty())
    for (std::size_t i = 0; i < model.n_owned(); ++i) owned_row[local[i]] = i;
  for (std::size_t i = 0; i < model.n_owned(); ++i) {
    std::size_t src = i;
    if (!mesh.tied_to.empty() && mesh.tied_to[local[i]] >= 0) {
      const auto it = owned_row.find(mesh.tied_to[local[i]]);
      FDEM_VERIFY(it != owned_row.end(), "snapshot: a tied node's target is on another rank");
      src = it->second;
    }
    d.node_global.push_back(fe.merged_node(local[i]));
    d.node_id.push_back(mesh.node_id[local[i]]);
    for (int k = 0; k < 3; ++k) {
      d.coords.push_back(k < dim ? mesh.coords[static_cast<std::size_t>(local[i]) * dim + k] : 0.0);
      d.displacement.push_back(k < dim ? u[src * dim + k] : 0.0);
      d.velocity.push_back(k < dim ? v[src * dim + k] : 0.0);
      // a force once: at the node it acts on (a tied node's row: its target's displacement, no force)
      d.interface_force.push_back(k < dim && static_cast<std::size_t>(k) < nf && src == i ? fi[i * nf + k] : 0.0);
    }
  }
  const auto& elems = model.local_elements();
  const auto& gp = model.gauss_states();
  for (std::size_t le = 0; le < elems.size(); ++le) {
    const std::int32_t e = elems[le];
    d.elem_id.push_back(mesh.elem_id[e]);
    d.elem_index.push_back(fe.merged_element(e));
    d.elem_type.push_back(static_cast<std::int8_t>(mesh.elem_type[e]));
    const std::int32_t* nodes;
    const int n = mesh.nodes_of(e, nodes);
    for (int k = 0; k < n; ++k) d.elem_conn.push_back(fe.merged_node(nodes[k]));
    d.elem_offset.push_back(static_cast<std::int64_t>(d.elem_conn.size()));
    const auto [g0, g1] = model.gauss_range(le);
    double s[6] = {0, 0, 0, 0, 0, 0}, st[6] = {0, 0, 0, 0, 0, 0};
    int plastic = 0;
    for (std::int32_t g = g0; g < g1; ++g) {
      for (int k = 0; k < 6; ++k) { s[k] += gp[g].stress[k]; st[k] += gp[g].strain[k]; }
      plastic += gp[g].yielded ? 1 : 0;
    }
    const double inv = g1 > g0 ? 1.0 / (g1 - g0) : 0.0;
    for (int k = 0; k < 6; ++k) { d.stress.push_back(s[k] * inv); d.strain.push_back(st[k] * inv); }
    d.plastic.push_back(plastic);
    d.material.push_back(mesh.elem_material[e]);
    d.active.push_back(model.element_active(le) ? 1 : 0);
  }
  return d;
}

}  // namespace

namespace {

/// fem.ties: each tied node becomes the nearest node of the target mesh within the tolerance
/// (a uniform grid of cells of the tolerance's size over the target's nodes); elements and the
/// merged node sets then use that node. Chains (a mesh tied to a mesh that is tied in its turn)
/// end at the last one.
void apply_ties(const CaseConfig& c, FeMeshes& out) {
  if (c.fem.ties.empty()) return;
  fem::Mesh& all = out.merged;
  const int dim = all.dim;
  all.tied_to.assign(all.n_nodes(), -1);
  for (const FeTieConfig& t : c.fem.ties) {
    const FeMeshes::Part& from = out.parts[t.mesh];
    const FeMeshes::Part& to = out.parts[t.to];
    const std::string where = "fem.ties: mesh '" + from.name + "' to '" + to.name + "'";
    std::vector<std::int32_t> nodes;
    if (t.node_set.empty()) {
      for (std::size_t i = 0; i < from.mesh.n_nodes(); ++i) nodes.push_back(static_cast<std::int32_t>(i));
    } else {
      auto it = from.mesh.node_sets.find(t.node_set);
      if (it == from.mesh.node_sets.end())
        throw InputError(c.file, t.line, where + ": mesh '" + from.name + "' has no node set '" + t.node_set +
                                             "' (valid: " + set_names(from.mesh.node_sets) + ")");
      nodes = it->second;
    }
    const double h = t.tolerance;
    auto cell = [&](const double* x) {
      std::array<long long, 3> k{0, 0, 0};
      for (int d = 0; d < dim; ++d) k[d] = static_cast<long long>(std::floor(x[d] / h));
      return k;
    };
    std::map<std::array<long long, 3>, std::vector<std::int32_t>> grid;
    for (std::size_t i = 0; i < to.mesh.n_nodes(); ++i) grid[cell(&to.mesh.coords[i * dim])].push_back(static_cast<std::int32_t>(i));
    std::size_t joined = 0;
    for (const std::int32_t i : nodes) {
      const double* x = &from.mesh.coords[static_cast<std::size_t>(i) * dim];
      const auto k0 = cell(x);
      std::int32_t best = -1;
      double best_d2 = h * h;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = (dim == 3 ? -1 : 0); dz <= (dim == 3 ? 1 : 0); ++dz) {
            auto it = grid.find({k0[0] + dx, k0[1] + dy, k0[2] + dz});
            if (it == grid.end()) continue;
            for (const std::int32_t j : it->second) {
              double d2 = 0;
              for (int d = 0; d < dim; ++d) d2 += std::pow(x[d] - to.mesh.coords[static_cast<std::size_t>(j) * dim + d], 2);
              if (d2 <= best_d2 && (best < 0 || d2 < best_d2 || j < best)) { best = j; best_d2 = d2; }
            }
          }
      if (best < 0) continue;
      all.tied_to[from.node_offset + i] = to.node_offset + best;
      ++joined;
    }
    if (joined == 0)
    {
      char tol[32];
      std::snprintf(tol, sizeof tol, "%g", t.tolerance);
      throw InputError(c.file, t.line, where + ": no node" + (t.node_set.empty() ? "" : " of node set '" + t.node_set + "'") +
                                           " lies within " + tol + " m of a node of '" + to.name + "' (fem.ties tolerance)");
    }
    out.tie_counts.push_back(static_cast<std::int64_t>(joined));
  }
  // chains end at their last node (a cycle of ties cannot chain: each mesh is tied once and
  // the search stops after as many links as there are meshes)
  for (std::size_t i = 0; i < all.n_nodes(); ++i) {
    std::int32_t r = all.tied_to[i];
    for (std::size_t hop = 0; r >= 0 && all.tied_to[r] >= 0 && hop < out.parts.size(); ++hop) r = all.tied_to[r];
    if (r == static_cast<std::int32_t>(i)) r = -1;
    all.tied_to[i] = r;
  }
  for (auto& n : all.elem_nodes)
    if (all.tied_to[n] >= 0) n = all.tied_to[n];
  for (auto& kv : all.node_sets) {
    for (auto& n : kv.second)
      if (all.tied_to[n] >= 0) n = all.tied_to[n];
    std::sort(kv.second.begin(), kv.second.end());
    kv.second.erase(std::unique(kv.second.begin(), kv.second.end()), kv.second.end());
  }
}

/// The mesh of one entry of fem.meshes, built or read.
void make_part_mesh(const CaseConfig& c, const FeMeshConfig& mc, FeMeshes::Part& part) {
  fem::Mesh& m = part.mesh;
  switch (mc.kind) {
    case FeMeshConfig::kBlock: {
      const std::array<double, 3> lo{mc.min.x, mc.min.y, mc.min.z}, hi{mc.max.x, mc.max.y, mc.max.z};
      const std::array<double, 3> vlo{mc.void_min.x, mc.void_min.y, mc.void_min.z},
          vhi{mc.void_max.x, mc.void_max.y, mc.void_max.z};
      if (mc.element == "shell4") {
        const int a = (mc.plate_axis + 1) % 3, b = (mc.plate_axis + 2) % 3;
        m = fem::make_shell_plate(lo, hi, mc.plate_axis, mc.divisions[a], mc.divisions[b]);
        break;
      }
      m = fem::make_block(lo, hi, mc.divisions[0], mc.divisions[1], mc.divisions[2], mc.has_void ? &vlo : nullptr,
                          mc.has_void ? &vhi : nullptr);
      if (mc.element == "hex8r" || mc.element == "hex8i")
        for (auto& t : m.elem_type) t = mc.element == "hex8r" ? fem::ElemType::kHex8R : fem::ElemType::kHex8I;
      break;
    }
    case FeMeshConfig::kGeogrid: {
      fem::GeogridSpec g;
      g.length = mc.length; g.width = mc.width; g.longitudinal_ribs = mc.longitudinal_ribs;
      g.transverse_ribs = mc.transverse_ribs; g.rib_width = mc.rib_width; g.thickness = mc.thickness;
      g.junction_thickness = mc.junction_thickness; g.clamp_length = mc.clamp_length;
      g.origin = {mc.origin.x, mc.origin.y, mc.origin.z};
      g.elements_per_rib_width = mc.elements_per_rib_width;
      g.elements_through_thickness = mc.elements_through_thickness;
      g.max_element_length = mc.max_element_length;
      g.clamp_gap = mc.clamp_gap;
      g.side_overhang = mc.side_overhang;
      try {
        m = fem::make_geogrid(g, part.geogrid);
        if (mc.element == "hex8i")
          for (auto& t : m.elem_type) t = fem::ElemType::kHex8I;
        part.is_geogrid = true;
      } catch (const InputError& e) {
        if (e.file() != "geogrid") throw;
        // the layout's own checks name no file: the mesh entry's line, what is wrong
        const std::string head = InputError::format("geogrid", 0, "");
        const std::string what = std::string(e.what()).substr(head.size());
        throw InputError(c.file, mc.line, "fem.meshes '" + mc.name + "'.geogrid: " + what);
      } catch (const std::exception& e) {
        throw InputError(c.file, mc.line, "fem.meshes '" + mc.name + "': " + e.what());
      }
      break;
    }
    case FeMeshConfig::kThesis:
      m.dim = mc.dim;
      fem::read_thesis_nodes(mc.nodes_file, mc.dim, m);
      fem::read_thesis_elements(mc.elements_file, element_type(mc.element), m, 0);
      break;
    case FeMeshConfig::kGmsh:
      fem::read_gmsh(mc.gmsh_file, m);
      break;
    case FeMeshConfig::kCylinder:
      m = fem::make_cylinder_shell({mc.base.x, mc.base.y, mc.base.z}, mc.radius, mc.length, mc.cyl_divisions[0],
                                   mc.cyl_divisions[1], mc.cyl_axis);
      break;
  }
}

/// Appends a part's nodes, elements and sets (named "mesh:set") to the merged mesh.
void merge_part(const FeMeshConfig& mc, FeMeshes::Part& part, fem::Mesh& all) {
  const fem::Mesh& m = part.mesh;
  part.node_offset = static_cast<std::int32_t>(all.n_nodes());
  part.elem_offset = static_cast<std::int32_t>(all.n_elements());
  all.node_id.insert(all.node_id.end(), m.node_id.begin(), m.node_id.end());
  all.coords.insert(all.coords.end(), m.coords.begin(), m.coords.end());
  for (std::size_t e = 0; e < m.n_elements(); ++e) {
    const std::int32_t* nodes;
    const int n = m.nodes_of(e, nodes);
    std::vector<std::int32_t> conn(nodes, nodes + n);
    for (auto& x : conn) x += part.node_offset;
    all.add_element(m.elem_id[e], m.elem_type[e], conn, mc.material);
  }
  for (const auto& kv : m.node_sets) {
    auto& dst = all.node_sets[mc.name + ":" + kv.first];
    for (std::int32_t n : kv.second) dst.push_back(n + part.node_offset);
  }
  for (const auto& kv : m.element_sets) {
    auto& dst = all.element_sets[mc.name + ":" + kv.first];
    for (std::int32_t e : kv.second) dst.push_back(e + part.elem_offset);
  }
}

}  // namespace

std::string ties_text(const CaseConfig& c, const FeMeshes& m) {
  std::string s;
  for (std::size_t i = 0; i < c.fem.ties.size() && i < m.tie_counts.size(); ++i) {
    const FeTieConfig& t = c.fem.ties[i];
    s += (s.empty() ? "" : "; ") + m.parts[t.mesh].name + (t.node_set.empty() ? "" : ":" + t.node_set) + " -> " +
         m.parts[t.to].name + ": " + std::to_string(m.tie_counts[i]) + " nodes";
  }
  return s;
}

void gather_fe_ranks(const fem::FeModel& model, MPI_Comm comm, RunInfo& info) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const double mine[4] = {static_cast<double>(model.local_elements().size()), static_cast<double>(model.n_owned()),
                          static_cast<double>(model.mesh().n_nodes()), peak_rss_mb()};
  std::vector<double> all(4 * static_cast<std::size_t>(size));
  MPI_Gather(mine, 4, MPI_DOUBLE, all.data(), 4, MPI_DOUBLE, 0, comm);
  info.fe_ranks.assign(static_cast<std::size_t>(size), FeRankRecord{});
  for (std::size_t r = 0; r < info.fe_ranks.size(); ++r)
    info.fe_ranks[r] = {static_cast<std::int64_t>(all[4 * r]), static_cast<std::int64_t>(all[4 * r + 1]),
                        static_cast<std::int64_t>(all[4 * r + 2]), all[4 * r + 3]};
}

FeMeshes build_fe_meshes(const CaseConfig& c) {
  FeMeshes out;
  fem::Mesh& all = out.merged;
  bool first = true;
  for (const FeMeshConfig& mc : c.fem.meshes) {
    FeMeshes::Part part;
    part.name = mc.name;
    make_part_mesh(c, mc, part);
    const fem::Mesh& m = part.mesh;
    if (m.n_elements() == 0) throw InputError(c.file, mc.line, "fem.meshes '" + mc.name + "': the mesh has no elements");
    if (first) all.dim = m.dim;
    else if (m.dim != all.dim) throw InputError(c.file, mc.line, "fem.meshes '" + mc.name + "': all meshes must have the same dimension");
    first = false;
    merge_part(mc, part, all);
    out.parts.push_back(std::move(part));
  }
  apply_ties(c, out);
  return out;
}

namespace {

/// The elements of every fem.remove entry (merged indices).
std::vector<std::vector<std::int32_t>> removal_lists(const CaseConfig& c, const FeMeshes& m) {
  std::vector<std::vector<std::int32_t>> out;
  for (const FeRemovalConfig& rm : c.fem.removals) {
    std::vector<std::int32_t>& el = out.emplace_back();
    for (std::int32_t e : m.parts[rm.mesh].mesh.element_sets.at(rm.element_set)) el.push_back(e + m.parts[rm.mesh].elem_offset);
  }
  return out;
}

/// fem.distribute: what rank 0 resolved on the whole mesh (boundary conditions, removals, the case
/// meshes' node offsets and the merged sizes), on every rank.
void bcast_resolved(FeSetup& fe, MPI_Comm comm) {
  Bytes b;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) {
    b.put(fe.bc.restraints);
    b.put(fe.bc.loads);
    b.put_size(fe.bc.reaction_groups.size());
    for (const auto& g : fe.bc.reaction_groups) { b.put(g.name); b.put(g.nodes); }
    b.put_size(fe.removals.size());
    for (const auto& r : fe.removals) b.put(r);
    b.put(fe.node_offsets);
    b.put_size(static_cast<std::uint64_t>(fe.n_nodes));
    b.put_size(static_cast<std::uint64_t>(fe.n_elements));
  }
  bcast_bytes(b.data(), 0, comm);
  if (rank == 0) return;
  b.get(fe.bc.restraints);
  b.get(fe.bc.loads);
  fe.bc.reaction_groups.resize(b.get_size());
  for (auto& g : fe.bc.reaction_groups) { b.get(g.name); b.get(g.nodes); }
  fe.removals.resize(b.get_size());
  for (auto& r : fe.removals) b.get(r);
  b.get(fe.node_offsets);
  fe.n_nodes = static_cast<std::int64_t>(b.get_size());
  fe.n_elements = static_cast<std::int64_t>(b.get_size());
}

/// fem.distribute: the boundary conditions of this rank's part, in its indices.
void localise_boundary(FeSetup& fe) {
  auto local = [&](std::int32_t n) { return find_sorted(fe.part.node_index, n); };
  auto keep = [&](auto& v) {
    std::size_t k = 0;
    for (auto& x : v)
      if (const std::int32_t l = local(x.node); l >= 0) { x.node = l; v[k++] = x; }
    v.resize(k);
  };
  keep(fe.bc.restraints);
  keep(fe.bc.loads);
  for (auto& g : fe.bc.reaction_groups) {
    std::size_t k = 0;
    for (std::int32_t n : g.nodes)
      if (const std::int32_t l = local(n); l >= 0) g.nodes[k++] = l;
    g.nodes.resize(k);
  }
}

}  // namespace

std::unique_ptr<FeSetup> make_fe_setup(const CaseConfig& c, MPI_Comm comm,
                                       const std::function<void(const FeMeshes&)>& on_whole) {
  auto fe = std::make_unique<FeSetup>();
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  fe->distributed = c.fem.distribute;
  fe->comm = comm;
  // fem.distribute: rank 0 alone builds the meshes and resolves the boundary conditions; an input
  // error there is every rank's.
  std::optional<InputError> err;
  if (!fe->distributed || rank == 0) {
    try {
      fe->meshes = build_fe_meshes(c);
      fe->bc = resolve(c, fe->meshes);
      if (c.fem.static_solver) check_static_restraints(c, fe->bc, fe->meshes.merged.dim);  // (on the whole mesh)
      fe->removals = removal_lists(c, fe->meshes);
      for (const auto& p : fe->meshes.parts) fe->node_offsets.push_back(p.node_offset);
      fe->n_nodes = static_cast<std::int64_t>(fe->meshes.merged.n_nodes());
      fe->n_elements = static_cast<std::int64_t>(fe->meshes.merged.n_elements());
      fe->structures = structures_json(fe->meshes);
      if (on_whole) on_whole(fe->meshes);
    } catch (const InputError& e) {
      if (!fe->distributed) throw;
      err = e;
    } catch (const std::bad_alloc&) {
      if (!fe->distributed) throw;
      err = InputError(c.file, c.fem.line, "fem.distribute: out of memory on rank 0 while building the meshes (rank 0 "
                                           "holds the whole mesh before it sends the parts)");
    } catch (const std::exception& e) {
      if (!fe->distributed) throw;
      // (the other ranks wait for rank 0: stop them all)
      std::fprintf(stderr, "fdem: rank 0: internal error while building the FE meshes: %s\n", e.what());
      MPI_Abort(comm, 1);
    }
  }
  if (fe->distributed) {
    agree_on_input_error(err, comm);
    bcast_resolved(*fe, comm);
  }
  if (c.fem.static_solver)
    for (const auto& m : c.fem.materials)
      if (m.mohr_coulomb)
        throw InputError(c.file, c.fem.line, "fem.solver: static is for elastic materials; material '" + m.name +
                                                 "' is mohr_coulomb (use solver: relaxation)");
  std::vector<fem::FeMaterial> mats;
  for (std::size_t k = 0; k < c.fem.materials.size(); ++k) mats.push_back(material_of(c, static_cast<int>(k)));
  fem::FeParams prm;
  const double gn = norm(c.gravity);
  if (c.fem.gravity && gn > 0) prm.gravity_dir = {c.gravity.x / gn, c.gravity.y / gn, c.gravity.z / gn};
  else for (auto& m : mats) m.unit_weight = 0;
  prm.damping = c.fem.damping;
  if (fe->distributed) {
    MeshPart mine = distribute_mesh(fe->meshes.merged, comm);  // (METIS on rank 0)
    fe->local = std::move(mine.mesh);
    fe->part = std::move(mine.part);
    fe->meshes.merged = fem::Mesh{};  // (rank 0 keeps neither the merged mesh nor the case meshes)
    for (FeMeshes::Part& p : fe->meshes.parts) p.mesh = fem::Mesh{};
    localise_boundary(*fe);
  } else {
    fe->part = partition_mesh(fe->meshes.merged, comm);  // (METIS on rank 0, broadcast)
  }
  const fem::Mesh& mesh = fe->mesh();
  fe->model = std::make_unique<fem::FeModel>(comm, mesh, fe->part, mats, prm);
  if (fe->node_offsets.size() > 1) {  // the unbalanced ratios per case mesh (a rigid part's
    std::vector<std::int32_t> group(mesh.n_nodes(), 0);  // reactions must not hide another's residual)
    for (std::size_t i = 0; i < mesh.n_nodes(); ++i) {
      const std::int64_t n = fe->merged_node(static_cast<std::int32_t>(i));
      group[i] = static_cast<std::int32_t>(std::upper_bound(fe->node_offsets.begin(), fe->node_offsets.end(), n) -
                                           fe->node_offsets.begin()) - 1;
    }
    fe->model->set_node_groups(group);
  }
  for (const auto& r : fe->bc.restraints) {
    fe->model->restrain(r.node, r.fixed, r.disp);
    fe->model->restrain_rotations(r.node, r.rot);
  }
  for (const auto& l : fe->bc.loads) fe->model->add_load(l.node, l.force);
  return fe;
}

bool fe_holds_mode(const CaseConfig& c) {
  return !c.fem.load_steps.empty() || !c.fem.displacement_steps.empty() || c.holds.present;
}

std::size_t fe_hold_count(const CaseConfig& c) {
  return std::max<std::size_t>({1, c.fem.load_steps.size(), c.fem.displacement_steps.size(), c.holds.count});
}

double fe_load_factor(const CaseConfig& c, std::size_t h) {
  return c.fem.load_steps.empty() ? 1.0 : c.fem.load_steps[h];
}

double fe_disp_factor(const CaseConfig& c, std::size_t h) {
  return c.fem.displacement_steps.empty() ? 1.0 : c.fem.displacement_steps[h];
}

bool begin_fe_hold(const CaseConfig& c, FeSetup& fe, std::size_t h) {
  fe.model->set_load_factor(fe_load_factor(c, h));
  fe.model->set_disp_factor(fe_disp_factor(c, h));
  bool removed = false;
  for (std::size_t k = 0; k < c.fem.removals.size(); ++k)
    if (c.fem.removals[k].at_hold == static_cast<int>(h)) {
      fe.model->remove_elements(fe.removals[k]);
      removed = true;
    }
  return removed;
}

FeSnapshotData fe_snapshot_data(const FeSetup& fe) { return snapshot_data(fe); }

double fe_max_displacement(const fem::FeModel& model, MPI_Comm comm) {
  const std::vector<double> u = model.owned_displacements();
  double m = 0;
  for (std::size_t i = 0; i + model.dim() <= u.size(); i += model.dim()) {
    double s = 0;
    for (int d = 0; d < model.dim(); ++d) s += u[i + d] * u[i + d];
    m = std::max(m, std::sqrt(s));
  }
  double g = 0;
  MPI_Allreduce(&m, &g, 1, MPI_DOUBLE, MPI_MAX, comm);
  return g;
}

void fe_check_health(const FeSetup& fe, const std::string& when, double unbalanced) {
  MPI_Comm comm = fe.comm;
  const fem::FeModel::Health h = fe.model->health();
  const fem::Mesh& mesh = fe.mesh();
  const int dim = mesh.dim;
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < mesh.n_nodes(); ++i)
    for (int d = 0; d < dim; ++d) {
      lo[d] = std::min(lo[d], mesh.coords[i * dim + d]);
      hi[d] = std::max(hi[d], mesh.coords[i * dim + d]);
    }
  if (fe.distributed) {  // (the bounding box of the whole mesh: of all parts)
    MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPI_DOUBLE, MPI_MIN, comm);
    MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPI_DOUBLE, MPI_MAX, comm);
  }
  double diag = 0;
  for (int d = 0; d < dim; ++d) diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
  diag = std::sqrt(diag);
  const bool nonfinite = h.nonfinite_node >= 0 || !std::isfinite(unbalanced);
  if (!nonfinite && !(h.max_u > diag)) return;
  const std::int64_t node = h.nonfinite_node >= 0 ? h.nonfinite_node : h.max_node;
  std::string where;
  if (node >= 0) {
    // The node's id, and the id of the first element (merged order) that has it: from the parts
    // that hold them (all ranks agree).
    long long ids[2] = {std::numeric_limits<long long>::min(), std::numeric_limits<long long>::min()};
    long long first = std::numeric_limits<long long>::max();
    for (std::size_t i = 0; i < mesh.n_nodes(); ++i)
      if (fe.merged_node(static_cast<std::int32_t>(i)) == node) {
        ids[0] = mesh.node_id[i];
        for (std::size_t e = 0; e < mesh.n_elements() && first == std::numeric_limits<long long>::max(); ++e) {
          const std::int32_t* nd;
          const int n = mesh.nodes_of(e, nd);
          if (std::find(nd, nd + n, static_cast<std::int32_t>(i)) != nd + n) {
            first = fe.merged_element(static_cast<std::int32_t>(e));
            ids[1] = mesh.elem_id[e];
          }
        }
        break;
      }
    if (fe.distributed) {
      long long f = first;
      MPI_Allreduce(&first, &f, 1, MPI_LONG_LONG, MPI_MIN, comm);
      if (f != first) ids[1] = std::numeric_limits<long long>::min();
      MPI_Allreduce(MPI_IN_PLACE, ids, 2, MPI_LONG_LONG, MPI_MAX, comm);
      first = f;
    }
    where = "node " + std::to_string(ids[0]);
    if (first != std::numeric_limits<long long>::max()) where += " (element " + std::to_string(ids[1]) + ")";
  }
  char buf[512];
  if (h.nonfinite_node >= 0)
    std::snprintf(buf, sizeof buf, "%s has a non-finite displacement or velocity", where.c_str());
  else if (!std::isfinite(unbalanced))
    std::snprintf(buf, sizeof buf, "the unbalanced-force ratio is %g (largest displacement %.4g m at %s)", unbalanced,
                  h.max_u, where.c_str());
  else
    std::snprintf(buf, sizeof buf, "the displacement of %s is %.4g m, more than the size of the mesh (%.4g m)",
                  where.c_str(), h.max_u, diag);
  throw RunDiverged(std::string("the FE run diverged in ") + when + ": " + buf +
                    "; likely cause: a load or prescribed displacement far too large for the structure (fem.loads, "
                    "load_steps, displacement_steps), or a structure not restrained against rigid-body motion "
                    "(fem.restraints)");
}

void check_static_restraints(const CaseConfig& c, const FeBoundary& bc, int dim) {
  bool held[3] = {false, false, false};
  for (const auto& r : bc.restraints)
    for (int d = 0; d < dim && d < 3; ++d) held[d] = held[d] || r.fixed[d];
  std::string free;
  for (int d = 0; d < dim && d < 3; ++d)
    if (!held[d]) free += std::string(free.empty() ? "" : ", ") + "xyz"[d];
  if (free.empty()) return;
  throw InputError(c.file, c.fem.line,
                   "fem.restraints: the model is not restrained in " + free +
                       " (no node has that displacement fixed or prescribed): the static stiffness matrix is singular "
                       "(rigid-body motion); restrain the structure (fem.restraints / fem.displacements) or use "
                       "solver: relaxation");
}

std::vector<std::string> fe_reaction_columns(const FeSetup& fe) {
  std::vector<std::string> rcols{"hold", "step"};
  for (const auto& g : fe.bc.reaction_groups)
    for (const char* k : {"_rx", "_ry", "_rz"}) rcols.push_back(g.name + k);
  return rcols;
}

std::vector<double> fe_reaction_row(const FeSetup& fe, double hold, double step) {
  std::vector<double> row{hold, step};
  for (const auto& g : fe.bc.reaction_groups) {
    const auto r = fe.model->reaction(g.nodes);
    row.insert(row.end(), {r[0], r[1], r[2]});
  }
  return row;
}

void check_fe_case(const CaseConfig& c, MPI_Comm comm) {
  const FeMeshes m = build_fe_meshes(c);
  const Resolved r = resolve(c, m);
  if (c.fem.static_solver) check_static_restraints(c, r, m.merged.dim);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return;
  std::printf("%s: ok\n", c.file.c_str());
  std::printf("  case        %s (finite elements only)\n", c.name.c_str());
  for (const auto& p : m.parts)
    std::printf("  mesh        %s: %zu nodes, %zu elements\n", p.name.c_str(), p.mesh.n_nodes(), p.mesh.n_elements());
  if (!c.fem.ties.empty()) std::printf("  ties        %s\n", ties_text(c, m).c_str());
  std::printf("  restrained  %zu node entries, %zu loaded nodes\n", r.restraints.size(), r.loads.size());
  const std::size_t holds = std::max<std::size_t>({1, c.fem.load_steps.size(), c.fem.displacement_steps.size()});
  std::printf("  solver      %s, %zu hold(s), tolerance %g\n", c.fem.static_solver ? "static (KSP)" : "dynamic relaxation",
              holds, c.fem.tolerance);
  std::printf("  output      %s\n", c.out_dir.c_str());
}

FeCheckpoint read_fe_checkpoint_for(const std::string& path, const fem::FeModel& model, std::int64_t n_nodes,
                                    std::int64_t n_elements, MPI_Comm comm) {
  h5::RowShare share;
  MPI_Comm_rank(comm, &share.part);
  MPI_Comm_size(comm, &share.parts);
  auto bad = [&](const std::string& what) { return InputError(path, 0, what); };
  const std::string not_this = "FE checkpoint does not belong to this case's mesh (";
  // The attributes and the datasets' sizes first (no row), then the rows in rounds: each rank
  // reads the next window of its 1/P of the node and Gauss-point rows and sends each row to the
  // rank that owns its node or element (partition/rendezvous.hpp). A rank holds its own rows and
  // one window's buffers at any time, never the whole state.
  FeCheckpoint ck;
  std::optional<InputError> err;
  try {
    share.limit = 0;
    ck = read_fe_checkpoint(path, share);
    if (ck.dim != model.node_dofs())
      throw bad("FE checkpoint has " + std::to_string(ck.dim) + " dofs per node, the case " +
                std::to_string(model.node_dofs()));
    if (ck.node_rows != n_nodes)
      throw bad("FE checkpoint has " + std::to_string(ck.node_rows) + " nodes, the case's mesh " + std::to_string(n_nodes));
  } catch (const InputError& e) {
    err = e;
  }
  agree_on_input_error(err, comm);
  fem::FeState& s = ck.state;
  const std::size_t nf = static_cast<std::size_t>(ck.dim);
  auto node_fields = [&](fem::FeState& st) {
    std::vector<std::vector<double>*> f = {&st.u, &st.v};
    if (s.has_prev) f.insert(f.end(), {&st.u_prev, &st.f_prev});
    return f;
  };
  const int node_width = static_cast<int>(1 + node_fields(s).size() * nf);
  constexpr int gp_width = 2 + 19;
  std::vector<std::int64_t> want_nodes, want_elems;
  for (std::size_t i = 0; i < model.n_owned(); ++i) want_nodes.push_back(model.whole_node(model.local_nodes()[i]));
  for (std::int32_t e : model.local_elements()) want_elems.push_back(model.whole_elem(e));
  {  // (the rows this rank will hold, allocated once)
    std::size_t n_gp = 0;
    for (std::size_t le = 0; le < model.local_elements().size(); ++le) {
      const auto r = model.gauss_range(le);
      n_gp += static_cast<std::size_t>(r.second - r.first);
    }
    s.node.reserve(want_nodes.size());
    for (std::vector<double>* f : node_fields(s)) f->reserve(want_nodes.size() * nf);
    s.gp_elem.reserve(n_gp), s.gp_k.reserve(n_gp), s.gp_data.reserve(n_gp * 19);
  }
  hsize_t window = hsize_t{1} << 17;  // rows per round (~22 MB of Gauss-point rows)
  if (const char* w = std::getenv("FDEM_FE_READ_ROWS"); w && std::atoll(w) > 0)  // (tests: many rounds)
    window = static_cast<hsize_t>(std::atoll(w));
  const hsize_t most = (static_cast<hsize_t>(std::max(ck.node_rows, ck.gp_rows)) + share.parts - 1) / share.parts;
  const hsize_t rounds = (most + window - 1) / window;  // (the same on every rank)
  for (hsize_t j = 0; j < rounds; ++j) {
    FeCheckpoint w;
    try {
      share.skip = j * window;
      share.limit = window;
      w = read_fe_checkpoint(path, share);
      for (std::int64_t n : w.state.node)
        if (n < 0 || n >= n_nodes) throw bad(not_this + "node index " + std::to_string(n) + ")");
      for (std::int64_t e : w.state.gp_elem)
        if (e < 0 || e >= n_elements) throw bad(not_this + "element index " + std::to_string(e) + ")");
    } catch (const InputError& e) {
      err = e;
    }
    agree_on_input_error(err, comm);  // (a bad row fails on the rank that read it)
    const std::vector<std::vector<double>*> wf = node_fields(w.state), sf = node_fields(s);
    std::vector<double> rows =
        send_rows(owners_of(w.state.node, want_nodes, n_nodes, comm), node_width, [&](std::size_t k, double* out) {
          *out++ = static_cast<double>(w.state.node[k]);
          for (const std::vector<double>* f : wf) out = std::copy(f->begin() + k * nf, f->begin() + (k + 1) * nf, out);
        }, comm);
    for (std::size_t p = 0; p < rows.size(); p += static_cast<std::size_t>(node_width)) {
      s.node.push_back(static_cast<std::int64_t>(rows[p]));
      const double* r = &rows[p + 1];
      for (std::vector<double>* f : sf) {
        f->insert(f->end(), r, r + nf);
        r += nf;
      }
    }
    rows = send_rows(owners_of(w.state.gp_elem, want_elems, n_elements, comm), gp_width, [&](std::size_t r, double* out) {
      out[0] = static_cast<double>(w.state.gp_elem[r]);
      out[1] = static_cast<double>(w.state.gp_k[r]);
      std::copy(w.state.gp_data.begin() + r * 19, w.state.gp_data.begin() + (r + 1) * 19, out + 2);
    }, comm);
    for (std::size_t p = 0; p < rows.size(); p += gp_width) {
      s.gp_elem.push_back(static_cast<std::int64_t>(rows[p]));
      s.gp_k.push_back(static_cast<std::int32_t>(rows[p + 1]));
      s.gp_data.insert(s.gp_data.end(), rows.begin() + static_cast<std::ptrdiff_t>(p + 2),
                       rows.begin() + static_cast<std::ptrdiff_t>(p + gp_width));
    }
  }
  // Every owned node once.
  std::sort(want_nodes.begin(), want_nodes.end());
  std::vector<std::int64_t> have(s.node);
  std::sort(have.begin(), have.end());
  const auto twice = std::adjacent_find(have.begin(), have.end());
  if (twice != have.end()) err = bad("FE checkpoint has node " + std::to_string(*twice) + " twice (the file is corrupted)");
  else if (have != want_nodes) {
    std::size_t k = 0;
    while (k < have.size() && have[k] == want_nodes[k]) ++k;
    err = bad(not_this + "it lacks node " + std::to_string(want_nodes[k]) + ")");
  }
  agree_on_input_error(err, comm);
  return ck;
}

namespace {

/// The holds of an FE run. Dynamic relaxation: a hold ends when the unbalanced-force ratio is
/// below fem.tolerance (checked every fem.check_every steps from the hold's start) or after
/// fem.max_steps. Static: each hold is one solve, counted as one step.
class FeHolds : public Schedule {
 public:
  FeHolds(const CaseConfig& c, FeSetup& fe, double& dt, int rank) : c_(c), fe_(fe), dt_(dt), rank_(rank) {}
  void check(RunState& st) override {
    const std::int64_t k = st.step - st.hold_start;  // steps of this hold
    if (!c_.fem.static_solver && k % c_.fem.check_every != 0 && k < c_.fem.max_steps) return;
    if (!c_.fem.static_solver) {
      unbalanced = fe_.model->unbalanced();
      char when[96];
      std::snprintf(when, sizeof when, "hold %zu (load factor %g), step %lld", st.hold + 1,
                    fe_load_factor(c_, st.hold), static_cast<long long>(st.step));
      fe_check_health(fe_, when, unbalanced);
    }
    checked_hold = st.hold;
    checked_k = k;
    if (c_.fem.static_solver || unbalanced < c_.fem.tolerance) {
      st.hold_done = true;
    } else if (k >= c_.fem.max_steps) {
      if (rank_ == 0)
        std::printf("fdem: hold %zu did not converge in %lld steps (unbalanced %.3e > %.1e); continuing\n", st.hold + 1,
                    static_cast<long long>(k), unbalanced, c_.fem.tolerance);
      st.hold_done = true;
    }
  }
  void begin_hold(const RunState& st) override { begin(st.hold); }
  /// Hold h's factors and element removals; a removal changes the stable step.
  void begin(std::size_t h) {
    current = h;
    if (begin_fe_hold(c_, fe_, h) && !c_.fem.static_solver) dt_ = c_.fem.safety * fe_.model->critical_dt();
  }
  double unbalanced = 0;  ///< at the last check (static: after the last solve)
  std::size_t current = 0;  ///< the hold being run
  std::size_t checked_hold = 0;
  std::int64_t checked_k = 0;

 private:
  const CaseConfig& c_;
  FeSetup& fe_;
  double& dt_;
  int rank_;
};

/// The outputs of an FE run: fe_history.csv, reactions.csv and an FE snapshot per hold,
/// fe_checkpoint.h5 after every hold (and on a signal inside one), run.json and the lines.
class FeOutput : public Observer {
 public:
  FeOutput(const CaseConfig& c, FeSetup& fe, const FeHolds& holds, const fem::FeModel::StaticSolveInfo& ksp,
           std::int64_t step0, bool restarted, std::size_t first_hold, bool quiet, MPI_Comm comm)
      : c_(c), fe_(fe), holds_(holds), ksp_(ksp), step0_(step0), quiet_(quiet), comm_(comm),
        dir_(c.out_dir), wall0_(MPI_Wtime()) {
    namespace fs = std::filesystem;
    MPI_Comm_rank(comm, &rank_);
    int size = 1;
    MPI_Comm_size(comm, &size);
    // Output (created only now: everything before has been checked).
    if (rank_ == 0) {
      fs::create_directories(dir_);
      write_case_yaml(c, dir_);
      std::ofstream(dir_ + "/structures.json") << fe.structures;
    }
    MPI_Barrier(comm);
    snaps_ = std::make_unique<FeSnapshotWriter>(dir_, "fe", comm);
    if (restarted) snaps_->adopt_existing(step0);  // fe.xdmf keeps the snapshots up to the checkpoint
    // On a restart the CSV rows of the holds still to run are dropped (first column: hold).
    const double keep = restarted ? static_cast<double>(first_hold) - 0.5 : 1e300;
    // Static runs also record what each KSP solve guarantees (fem::FeModel::StaticSolveInfo).
    std::vector<std::string> hist_cols = {"hold",      "step",    "load_factor",     "disp_factor",
                                          "unbalanced", "damping", "max_displacement"};
    if (c.fem.static_solver)
      for (const char* k : {"ksp_iterations", "ksp_rtol", "ksp_residual", "ksp_condition", "ksp_error_bound"})
        hist_cols.push_back(k);
    hist_ = std::make_unique<CsvWriter>(dir_ + "/fe_history.csv", hist_cols, comm, restarted, keep);
    reac_ = std::make_unique<CsvWriter>(dir_ + "/reactions.csv", fe_reaction_columns(fe), comm, restarted, keep);
    info_.version = FDEM_VERSION;
    info_.case_name = c.name;
    info_.case_file = c.file;
    info_.overrides = c.overrides;
    info_.ranks = size;
  }
  RunInfo& info() { return info_; }
  double fe_time = 0;  ///< seconds in the FE steps and checks
  std::int64_t step = 0;

  /// `collective`: every rank calls it (not on an error of one rank), and each rank's share and
  /// memory are gathered.
  void fill_info(const char* status, const std::string& message = "", bool collective = true) {
    if (collective) gather_fe_ranks(*fe_.model, comm_, info_);
    info_.status = status;
    info_.message = message;
    info_.steps = step;
    info_.wall_time = MPI_Wtime() - wall0_;
    info_.timings = {{"fe_steps", fe_time}};
    info_.start_step = step0_;
    // Static runs count a hold as a step but update no elements explicitly: reported as 0.
    info_.element_updates_per_second =
        fe_time > 0 && !c_.fem.static_solver
            ? static_cast<double>(step - step0_) * fe_.model->n_elements_global() / fe_time
            : 0;
    if (rank_ == 0) write_run_json(dir_ + "/run.json", info_);
  }
  void on_start(const RunState&) override { snapshot(0, 0.0); }
  void on_hold_end(const RunState& st) override {
    const std::size_t h = st.hold;
    const double lf = fe_load_factor(c_, h), df = fe_disp_factor(c_, h);
    std::vector<double> row = {static_cast<double>(h), static_cast<double>(step), lf, df, holds_.unbalanced,
                               fe_.model->damping_used(), fe_max_displacement(*fe_.model, comm_)};
    if (c_.fem.static_solver)
      row.insert(row.end(), {static_cast<double>(ksp_.iterations), ksp_.rtol, ksp_.residual, ksp_.condition,
                             ksp_.error_bound()});
    hist_->row(row);
    reac_->row(fe_reaction_row(fe_, static_cast<double>(h), static_cast<double>(step)));
    snapshot(step, static_cast<double>(h + 1));
    checkpoint(st, true);
    if (rank_ == 0 && !quiet_) {
      std::printf("hold %zu/%zu: load factor %g, displacement factor %g, unbalanced %.3e, step %lld\n", h + 1,
                  st.holds, lf, df, holds_.unbalanced, static_cast<long long>(step));
      std::fflush(stdout);
    }
  }
  void on_progress(const RunState& st) override {
    if (c_.fem.static_solver || rank_ != 0) return;
    std::printf("hold %zu/%zu  step %lld  unbalanced %.3e (tolerance %.1e)\n", holds_.checked_hold + 1, st.holds,
                static_cast<long long>(holds_.checked_k), holds_.unbalanced, c_.fem.tolerance);
    std::fflush(stdout);
  }
  void on_signal(const RunState& st, int sig) override {
    // A signal at a hold's end stops the run after it: its checkpoint and snapshot were just
    // written (a static solve cannot be interrupted inside). Inside a hold (relaxation) it
    // stops at once.
    if (st.hold_done) {
      // (the loop has moved on to the next hold: st.hold, 0-based, is the number of the one done)
      if (rank_ == 0)
        std::printf("fdem: signal %d after hold %zu (step %lld): %s/fe_checkpoint.h5 holds it; stopping\n", sig,
                    st.hold, static_cast<long long>(step), dir_.c_str());
    } else {
      if (rank_ == 0)
        std::printf("fdem: signal %d in hold %zu at step %lld: writing %s/fe_checkpoint.h5 and stopping\n", sig,
                    st.hold + 1, static_cast<long long>(step), dir_.c_str());
      checkpoint(st, false);
      snapshot(step, static_cast<double>(st.hold + 1));
    }
    end("interrupted");
  }
  void on_finish(const RunState&) override { end("finished"); }
  void on_error(const RunState&, bool diverged, const std::string& what) noexcept override {
    try {
      fill_info(diverged ? "diverged" : "failed", what, diverged);
    } catch (...) {
    }
  }

 private:
  void snapshot(std::int64_t k, double t) { snaps_->write(k, t, snapshot_data(fe_)); }
  void checkpoint(const RunState& st, bool done) {
    FeCheckpoint ck;
    ck.hold = static_cast<std::int64_t>(st.hold);
    ck.hold_done = done ? 1 : 0;
    ck.step = step;
    ck.hold_start = st.hold_start;
    ck.dim = fe_.model->node_dofs();
    ck.state = fe_.model->state();
    write_fe_checkpoint(dir_ + "/fe_checkpoint.h5", comm_, ck);
  }
  void end(const char* status) {
    fill_info(status);
    if (rank_ == 0 && !quiet_)
      std::printf("fdem: %s after %lld steps in %.2f s (%.3e element updates/s); results in %s\n", status,
                  static_cast<long long>(step), info_.wall_time, info_.element_updates_per_second, dir_.c_str());
  }
  const CaseConfig& c_;
  FeSetup& fe_;
  const FeHolds& holds_;
  const fem::FeModel::StaticSolveInfo& ksp_;
  std::int64_t step0_;
  bool quiet_;
  MPI_Comm comm_;
  int rank_ = 0;
  std::string dir_;
  double wall0_;
  std::unique_ptr<FeSnapshotWriter> snaps_;
  std::unique_ptr<CsvWriter> hist_, reac_;
  RunInfo info_;
};

}  // namespace

int run_fe_case(const CaseConfig& c, const RunOptions& opt, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const std::unique_ptr<FeSetup> fe = make_fe_setup(c, comm);
  fem::FeModel& model = *fe->model;
  // Restart: the state, the hold to continue and the step count come from an FE checkpoint.
  std::size_t first_hold = 0;
  std::int64_t step0 = 0;
  std::int64_t resume_hold_start = -1;  // a hold interrupted by a signal: the step it began
  const bool restarted = !opt.restart.empty();
  if (restarted) {
    const FeCheckpoint ck = read_fe_checkpoint_for(opt.restart, model, fe->n_nodes, fe->n_elements, comm);
    model.restore(ck.state);
    first_hold = static_cast<std::size_t>(ck.hold + (ck.hold_done ? 1 : 0));
    step0 = ck.step;
    if (!ck.hold_done && ck.hold_start >= 0 && ck.hold_start <= ck.step) resume_hold_start = ck.hold_start;
  }
  const std::size_t holds = fe_hold_count(c);
  double dt = 0;
  fem::FeModel::StaticSolveInfo ksp;
  FeHolds schedule(c, *fe, dt, rank);
  FeOutput out(c, *fe, schedule, ksp, step0, restarted, first_hold, opt.quiet, comm);
  out.step = step0;
  out.fill_info("running");
  if (!c.fem.static_solver) {
    dt = c.fem.safety * model.critical_dt();
    out.info().dt = dt;
  }
  if (rank == 0 && !opt.quiet) {
    char how[96];
    if (c.fem.static_solver) std::snprintf(how, sizeof how, "static solve (KSP)");
    else std::snprintf(how, sizeof how, "dynamic relaxation, dt %.3e s", dt);
    std::printf("fdem %s: FE case '%s' on %d rank(s): %zu nodes, %zu elements, %zu hold(s), %s\n", FDEM_VERSION,
                c.name.c_str(), size, static_cast<std::size_t>(fe->n_nodes), static_cast<std::size_t>(fe->n_elements), holds,
                how);
    if (!c.fem.ties.empty()) std::printf("fdem: tied %s\n", ties_text(c, fe->meshes).c_str());
  }
  if (restarted && rank == 0 && !opt.quiet)
    std::printf("fdem: restarting from %s at hold %zu, step %lld\n", opt.restart.c_str(), first_hold + 1,
                static_cast<long long>(step0));
  if (first_hold >= holds) {  // a checkpoint of the last hold's end: nothing left to run
    out.on_finish(RunState{});
    return 0;
  }

  // One static solve per hold, counted as one step: hold h (0-based) of a run from the start
  // ends at step h + 1, so every hold has its own snapshot, xdmf entry and history row.
  auto advance = [&] {
    const double t0 = MPI_Wtime();
    if (!c.fem.static_solver) {
      model.step(dt);
    } else {
      try {
        ksp = model.solve_static();
      } catch (const std::runtime_error& e) {
        const bool nan = std::string(e.what()).find("NANORINF") != std::string::npos;
        const std::size_t h = schedule.current;
        char when[64];
        std::snprintf(when, sizeof when, "hold %zu (load factor %g)", h + 1, fe_load_factor(c, h));
        throw RunDiverged(std::string("the FE run diverged in ") + when + ": " + e.what() + "; likely cause: " +
                          (nan ? "a load or prescribed displacement far too large (non-finite values in the solve)"
                               : "the structure is not fully restrained against rigid-body motion (fem.restraints: "
                                 "translations and rotations) or it is a mechanism"));
      }
      schedule.unbalanced = model.unbalanced();
    }
    ++out.step;
    if (c.fem.static_solver) {
      char when[96];
      std::snprintf(when, sizeof when, "hold %zu (load factor %g), step %lld", schedule.current + 1,
                    fe_load_factor(c, schedule.current), static_cast<long long>(out.step));
      fe_check_health(*fe, when, schedule.unbalanced);
    }
    out.fe_time += MPI_Wtime() - t0;
  };
  RunControl::Params rp;
  rp.end_step = std::numeric_limits<std::int64_t>::max();
  rp.holds = holds;
  rp.first_hold = first_hold;
  rp.hold_start = resume_hold_start >= 0 ? resume_hold_start : step0;
  rp.poll_every = c.fem.static_solver ? 1 : c.fem.check_every;
  rp.poll_from_hold_start = true;
  rp.quiet = opt.quiet;
  rp.progress_interval = c.progress_interval;
  RunControl run(comm, rp, advance, [&] { return out.step; });
  schedule.checked_hold = first_hold;
  schedule.begin(first_hold);
  run.set_schedule(schedule);
  run.add(out);
  return run.run(!restarted);
}

}  // namespace fdem

namespace fdem {

void write_structures(const FeMeshes& m, const std::string& dir) {
  std::ofstream(dir + "/structures.json") << structures_json(m);
}

std::string structures_json(const FeMeshes& m) {
  std::ostringstream o;
  o << "{\n  \"meshes\": [";
  for (std::size_t k = 0; k < m.parts.size(); ++k) {
    const FeMeshes::Part& p = m.parts[k];
    const int dim = p.mesh.dim;
    std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
    for (int d = 0; d < dim; ++d) { lo[d] = 1e300; hi[d] = -1e300; }
    for (std::size_t i = 0; i < p.mesh.n_nodes(); ++i)
      for (int d = 0; d < dim; ++d) {
        lo[d] = std::min(lo[d], p.mesh.coords[i * dim + d]);
        hi[d] = std::max(hi[d], p.mesh.coords[i * dim + d]);
      }
    o << (k ? "," : "") << "\n    {\"name\": " << json_string(p.name) << ", \"nodes\": " << p.mesh.n_nodes()
      << ", \"elements\": " << p.mesh.n_elements() << ", \"node_offset\": " << p.node_offset
      << ", \"element_offset\": " << p.elem_offset << ", \"min\": " << json_array({lo[0], lo[1], lo[2]})
      << ", \"max\": " << json_array({hi[0], hi[1], hi[2]});
    if (p.is_geogrid) {
      const fem::GeogridInfo& g = p.geogrid;
      o << ",\n     \"geogrid\": {\"aperture_x\": " << json_number(g.aperture_x) << ", \"aperture_y\": " << json_number(g.aperture_y)
        << ", \"pitch_x\": " << json_number(g.pitch_x) << ", \"pitch_y\": " << json_number(g.pitch_y)
        << ", \"clamp_gap\": " << json_number(g.clamp_gap) << ", \"junction_thickness\": " << json_number(g.junction_thickness)
        << ", \"plan_area\": " << json_number(g.plan_area) << ", \"volume\": " << json_number(g.volume)
        << ",\n      \"transverse_x\": " << json_array(g.transverse_x) << ",\n      \"longitudinal_y\": "
        << json_array(g.longitudinal_y) << "}";
    }
    o << "}";
  }
  o << "\n  ]\n}\n";
  return o.str();
}

}  // namespace fdem
