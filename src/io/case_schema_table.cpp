// The case schema's table: every key of a case file, section by section (src/io/case_schema.hpp).
//
// Sources: the key lists of the reader's check_keys calls (src/io/case_file.cpp; a section's keys,
// or a variant's, are in exactly the order of its call: the "unknown key" message lists them), the
// range table kRanges of the same file (a key's `range` is the row find_range gives its path, the
// first matching row) and the key tables of docs/case-format.md (type, units, default and meaning,
// verbatim; keys the docs document together are split, keys the docs lack are described from the
// reader).
//
// Conventions beyond the header's:
//  - `range_unit` is set where the range table's unit differs from `units`; a range table unit ""
//    (dimensionless) is left "", and `units` "–" (the docs' dimensionless) means no unit.
//  - A section with `variants` and an empty `variant_key` has forms the reader tells apart by the
//    shape of the mapping, not by a key's value: `walls.motion` ("single": one motion; "phase": an
//    entry of a motion schedule, the list form) and `fem.loads` ("nodal", "pressure"). The
//    section's `keys` are the union; `key_names(path)` without a variant gives all of them.
//  - kStrings keys whose entries are words of a fixed set (degrees of freedom) list them in
//    `values`.
//  - Paths read with read_box ({min, max}) each have their own section: domain,
//    particles.generate.box, constraints.region, fem.meshes.block.void, fem.restraints.region,
//    fem.loads.region, fem.displacements.region, packing.box. Paths read with read_size: the
//    sections particles.generate.size and packing.size (the same variants).
#include "io/case_schema.hpp"

namespace fdem::schema {
namespace {

/// A row of the range table: lo <= |v| <= hi, the sign the key allows, the unit it is given in.
struct R {
  double lo = 0, hi = 0;
  char sign = '~';
  const char* unit = "";
};
const R kNoRange{};

Key make(const std::string& name, Type type, const std::string& type_text, const std::string& units,
         const std::string& def, const std::string& help, const R& r = kNoRange, const std::string& section = "",
         std::vector<std::string> values = {}) {
  Key k;
  k.name = name;
  k.type = type;
  k.type_text = type_text;
  k.units = units;
  k.def = def;
  k.help = help;
  k.section = section;
  k.values = std::move(values);
  k.range = Range{r.lo, r.hi, r.sign};
  if (k.range.defined() && r.unit[0] && units != r.unit) k.range_unit = r.unit;
  return k;
}

/// A key whose default depends on other keys (Key::conditional).
Key conditional(Key k) {
  k.conditional = true;
  return k;
}

Key num(const std::string& name, const std::string& type_text, const std::string& units, const std::string& def,
        const std::string& help, const R& r = kNoRange) {
  return make(name, Type::kNumber, type_text, units, def, help, r);
}
Key integer(const std::string& name, const std::string& type_text, const std::string& units, const std::string& def,
            const std::string& help, const R& r = kNoRange) {
  return make(name, Type::kInteger, type_text, units, def, help, r);
}
Key vec3(const std::string& name, const std::string& type_text, const std::string& units, const std::string& def,
         const std::string& help, const R& r = kNoRange) {
  return make(name, Type::kVec3, type_text, units, def, help, r);
}
Key numbers(const std::string& name, const std::string& type_text, const std::string& units, const std::string& def,
            const std::string& help, const R& r = kNoRange) {
  return make(name, Type::kNumbers, type_text, units, def, help, r);
}
Key boolean(const std::string& name, const std::string& type_text, const std::string& def, const std::string& help) {
  return make(name, Type::kBool, type_text, "", def, help);
}
Key str(const std::string& name, const std::string& type_text, const std::string& units, const std::string& def,
        const std::string& help) {
  return make(name, Type::kString, type_text, units, def, help);
}
Key strings(const std::string& name, const std::string& type_text, const std::string& def, const std::string& help,
            std::vector<std::string> values = {}) {
  return make(name, Type::kStrings, type_text, "", def, help, kNoRange, "", std::move(values));
}
Key word(const std::string& name, const std::string& type_text, std::vector<std::string> values,
         const std::string& def, const std::string& help) {
  return make(name, Type::kEnum, type_text, "", def, help, kNoRange, "", std::move(values));
}
Key map(const std::string& name, const std::string& type_text, const std::string& units, const std::string& def,
        const std::string& help, const std::string& section) {
  return make(name, Type::kMap, type_text, units, def, help, kNoRange, section);
}
Key list(const std::string& name, const std::string& type_text, const std::string& units, const std::string& def,
         const std::string& help, const std::string& section) {
  return make(name, Type::kList, type_text, units, def, help, kNoRange, section);
}
Key any(const std::string& name, const std::string& type_text, const std::string& units, const std::string& def,
        const std::string& help, const R& r = kNoRange, const std::string& section = "") {
  return make(name, Type::kAny, type_text, units, def, help, r, section);
}

// ---- ranges shared by several keys (rows of kRanges) ----
const R kCoord{1e-300, 1e5, '~', "m"};         // *.min, *.max, *.point, *.vertices, *.offset, *.base, *.x
const R kVelocity{1e-12, 1e4, '~', "m/s"};     // *.velocity
const R kDirection{1e-12, 1e6, '~', ""};       // *.normal, *.axis, *.direction
const R kFriction{1e-9, 100, '0', "(tan phi)"};  // *.friction
const R kKtKn{1e-9, 10, '0', ""};              // *.kt_kn
const R kRolling{1e-9, 100, '0', ""};          // *.rolling_stiffness, *.rolling_limit
const R kSeed{1, 9e15, '0', ""};               // *.seed
const R kMaxAttempts{1, 1e8, '+', ""};         // *.max_attempts
const R kArea{1e-12, 1e6, '+', "m^2"};         // *.area
const R kDiameter{1e-6, 10, '+', "m"};         // *.size.d, min, max, mean, sizes
const R kGeogridLength{1e-6, 1e3, '0', "m"};   // fem.meshes.geogrid.*
const R kSettleSteps{1, 1e12, '0', "steps"};   // packing.settle.*
const R kReport{1e-9, 1e3, '+', "m"};          // packing.report.*

const std::vector<std::string> kDofs3 = {"x", "y", "z"};
const std::vector<std::string> kDofs6 = {"x", "y", "z", "rx", "ry", "rz"};

Section sec(const std::string& path, std::vector<Key> keys) {
  Section s;
  s.path = path;
  s.keys = std::move(keys);
  return s;
}

/// A box {min, max} read by read_box.
Section box(const std::string& path) {
  return sec(path,
             {vec3("min", "`[x, y, z]`", "m", "**required**", "the box's lower corner", kCoord),
              vec3("max", "`[x, y, z]`", "m", "**required**", "the box's upper corner; `min < max` in every direction", kCoord)});
}

/// A size distribution (read_size): the keys by `distribution`.
Section size(const std::string& path) {
  Section s;
  s.path = path;
  s.keys = {
      word("distribution", "`constant`, `uniform`, `normal` or `sieve`", {"constant", "uniform", "normal", "sieve"}, "**required**", "selects the kind; each kind accepts only its own keys"),
      num("d", "number > 0", "m", "**required** (`constant`)", "`constant`: every diameter is `d`", kDiameter),
      num("min", "number > 0", "m", "**required** (`uniform`); none (`normal`, `sieve`)", "`uniform`: uniform in [min, max] (0 < min ≤ max); `normal`, `sieve`: truncation, draws below it are redrawn (truncated, not clamped); a sieve curve whose `passing` at the smallest sieve is above 0 places that mass in [min, sizes[0]] and then needs `min`. Applies to the unscaled curve", kDiameter),
      num("max", "number > 0", "m", "**required** (`uniform`); none (`normal`, `sieve`)", "`uniform`: uniform in [min, max]; `normal`, `sieve`: truncation, draws above it are redrawn. Applies to the unscaled curve", kDiameter),
      num("mean", "number > 0", "m", "**required** (`normal`)", "`normal`: the mean diameter. Without `min`, `mean ≥ 2 sd` is required", kDiameter),
      num("sd", "number ≥ 0", "m", "**required** (`normal`)", "`normal`: the standard deviation; draws outside [min, max] or ≤ 0 are redrawn (truncated, not clamped)", R{1e-9, 10, '0', "m"}),
      numbers("sizes", "list of numbers", "m", "**required** (`sieve`)", "`sieve`: the sieve sizes, strictly ascending (at least two)", kDiameter),
      numbers("passing", "list of numbers", "%", "**required** (`sieve`)", "`sieve`: the mass % passing each size, non-decreasing, in [0, 100], last value 100", R{1e-9, 100, '0', "%"}),
      num("scale", "number > 0", "–", "`1`", "multiplies every drawn diameter (the thesis's up-scaling factor); `min`/`max` truncations apply to the unscaled curve", R{1e-6, 1e6, '+', ""}),
  };
  s.variant_key = "distribution";
  s.variants = {{"constant", {"distribution", "d", "scale"}},
                {"uniform", {"distribution", "min", "max", "scale"}},
                {"normal", {"distribution", "mean", "sd", "min", "max", "scale"}},
                {"sieve", {"distribution", "sizes", "passing", "min", "max", "scale"}}};
  return s;
}

/// An entry of fem.restraints / fem.loads / fem.displacements (read_fem_nodal): `value` is the
/// list's value key (restraints: fixed, loads: total, displacements: value).
Section nodal(const std::string& path, const std::string& file_help, Key value) {
  return sec(path,
             {str("mesh", "string", "", "**required**", "an `fem.meshes` name"),
              str("node_set", "string", "", "–", "a node set of the mesh; give one of `node_set`, `region`, `file`"),
              map("region", "`{min, max}`", "m", "–", "the nodes inside a box", path + ".region"),
              str("file", "path", "", "–", file_help),
              std::move(value)});
}

}  // namespace

const std::vector<Section>& sections() {
  static const std::vector<Section> table = [] {
    std::vector<Section> t;

    // ---------------------------------------------------------------- top level (kTopKeys)
    t.push_back(sec("",
                 {
                     str("name", "string", "", "the case file's stem (`settle` for `settle.yaml`)", "case name; used for the default output directory; printable UTF-8 (no control characters)"),
                     map("domain", "`{min: [x,y,z], max: [x,y,z]}`", "m", "**required** (not in pure FE cases)", "simulation box; `min < max` in every direction. Initial particles must have their centres inside it (else an error); particles whose centre leaves it during the run are removed", "domain"),
                     vec3("gravity", "`[gx, gy, gz]`", "m/s²", "`[0, 0, -9.81]`", "gravitational acceleration, on the particles (and on FE bodies with `fem.gravity`)", R{1e-12, 1e4, '~', "m/s^2"}),
                     map("time", "mapping", "", "**required** (not in pure FE cases)", "see [time](#time)", "time"),
                     num("damping", "number in [0, 1)", "–", "`0.2`", "Cundall local non-viscous damping λ (DESIGN.md 4.1)", R{1e-12, 1, '0', ""}),
                     map("neighbor", "`{skin: …}`", "", "`{skin: auto}`", "Verlet-list skin: a positive length (m) or `auto` = 0.3 × the largest radius. Lists are rebuilt when a particle has moved more than skin/2 (global check every step); the ghost layer is 2·r_max + skin wide", "neighbor"),
                     map("decomposition", "`{grid: …}`", "", "`{grid: auto}`", "how the domain is split over the ranks, see [decomposition](#decomposition)", "decomposition"),
                     list("materials", "list", "", "**required**, non-empty", "see [materials](#materials)", "materials"),
                     list("interactions", "list", "", "none", "pair overrides, see [interactions](#interactions)", "interactions"),
                     list("particles", "list", "", "**required**, non-empty (may be omitted with `restart`)", "see [particles](#particles)", "particles"),
                     list("walls", "list", "", "none", "see [walls](#walls)", "walls"),
                     list("constraints", "list", "", "none", "see [constraints](#constraints)", "constraints"),
                     map("output", "mapping", "", "see [output](#output)", "the output directory and how often snapshots, history rows and checkpoints are written", "output"),
                     map("progress", "`{interval: s}`", "s", "`{interval: 5}`", "seconds between progress lines (> 0)", "progress"),
                     map("restart", "`{from: path}`", "", "none", "continue from a checkpoint file", "restart"),
                     map("fem", "mapping", "", "none", "finite elements, see [fem](#fem)", "fem"),
                     map("coupling", "mapping", "", "none; **required** when a case has both particles and `fem`", "the FE–DE coupling, see [coupling](#coupling)", "coupling"),
                     map("measure", "mapping", "", "none", "micro-mechanics measurements, see [measure](#measure) (not in pure FE cases)", "measure"),
                     map("lab", "mapping", "", "none", "a direct shear or triaxial test made of walls: `lab.csv`, see [lab](#lab)", "lab"),
                     map("packing", "mapping", "", "none", "pack a specimen before the run, see [packing](#packing); with `packing`, `particles` and `time.steps`/`duration` may be omitted (no steps: the case ends after packing)", "packing"),
                     map("holds", "mapping", "", "none", "load holds on walls (a footing's pressure in increments, or a wall moved in steps, each held to equilibrium), see [holds](#holds) (particle and coupled runs)", "holds"),
                     word("contact_model", "`linear` \\| `hertz_mindlin`", {"linear", "hertz_mindlin"}, "`linear`", "the contact model of every pair of materials that no `interactions` entry gives a `model`; see [contact models](#contact-models) (not in pure FE cases)"),
                     word("rolling_law", "`incremental` \\| `total`", {"incremental", "total"}, "`incremental`", "the rolling law of every material that gives none; see [rolling laws](#rolling-laws) (not in pure FE cases)"),
                 }));
    t.push_back(box("domain"));

    // ---------------------------------------------------------------- time
    t.push_back(sec("time",
                 {
                     any("dt", "positive number or `auto`", "s", "`auto`", "time step; `auto` = `safety` × Δt_cr with Δt_cr = min over particles of sqrt(m / (2·E·r)) (one particle against a rigid wall of its own stiffness; the safety factor covers the many contacts of a dense packing). On a restart the checkpoint's `dt` is used", R{1e-12, 1, '+', "s"}),
                     num("safety", "number in (0, 1]", "–", "`0.3`", "factor on the critical step when `dt` is `auto`", R{1e-6, 1, '+', ""}),
                     integer("steps", "positive integer", "–", "–", "number of steps; on a restart, the step number at which the run ends (the checkpoint's step counts)", R{1, 1e12, '+', ""}),
                     num("duration", "positive number", "s", "–", "simulated time (the engine derives the step count)", R{1e-12, 1e6, '+', "s"}),
                     num("stop_unbalanced", "number ≥ 0", "–", "`0`", "stop early when the unbalanced-force ratio drops below it; 0 = never", R{1e-12, 1e3, '0', ""}),
                     num("stop_kinetic_ratio", "number ≥ 0", "–", "`0.001`", "with `stop_unbalanced`: the run stops only when the grains' kinetic energy per grain (translational and rotational) is also below this times m̄·g·d̄ (the mean grain mass and diameter at the start), so that a cloud in free fall (few contacts, each balanced) does not end it; 0 = not checked; not checked without gravity", R{1e-12, 1e6, '0', ""}),
                 }));

    // ---------------------------------------------------------------- materials, interactions
    t.push_back(sec("materials",
                 {
                     str("name", "string", "", "**required**", "unique name"),
                     num("young", "number > 0", "Pa", "**required**", "Young's modulus E; linear model: particle normal stiffness k_n = 2·E·r; Hertz-Mindlin: enters E* and G*", R{1e3, 1e13, '+', "Pa"}),
                     num("density", "number > 0", "kg/m³", "**required**", "solid density of the grains (their mass)", R{1, 1e5, '+', "kg/m^3"}),
                     num("kt_kn", "number ≥ 0", "–", "`0.25`", "α = K_T / K_N (linear pairs only; Hertz-Mindlin's K_T comes from G*)", kKtKn),
                     num("friction", "number ≥ 0", "–", "`0.5`", "tan φ_μ (Coulomb coefficient, not the angle)", kFriction),
                     num("rolling_stiffness", "number ≥ 0", "–", "`0`", "β_r (0: no rolling resistance)", kRolling),
                     num("rolling_limit", "number ≥ 0", "–", "`0`", "η_r", kRolling),
                     word("rolling_law", "`incremental` \\| `total`", {"incremental", "total"}, "the case's `rolling_law`", "the rolling law of this material's pairs (two materials of different laws: their pair's law is required in `interactions`); see [rolling laws](#rolling-laws)"),
                     num("poisson", "number in (-1, 0.5)", "–", "`0.25`", "Poisson's ratio ν; used by Hertz-Mindlin pairs only (E*, G*) and the Rayleigh time-step bound", R{1e-9, 1, '~', ""}),
                 }));
    t.push_back(sec("interactions",
                 {
                     strings("materials", "`[name, name]`", "**required**", "the pair (may be the same name twice)"),
                     num("friction", "number ≥ 0", "", "pair default", "the pair's tan φ; at least one of `friction`, `kt_kn`, `rolling_stiffness`, `rolling_limit`, `model` or `rolling_law` is required", kFriction),
                     num("kt_kn", "number ≥ 0", "", "pair default", "the pair's α = K_T / K_N; at least one of `friction`, `kt_kn`, `rolling_stiffness`, `rolling_limit`, `model` or `rolling_law` is required", kKtKn),
                     num("rolling_stiffness", "number ≥ 0", "", "pair default", "the pair's β_r; at least one of `friction`, `kt_kn`, `rolling_stiffness`, `rolling_limit`, `model` or `rolling_law` is required", kRolling),
                     num("rolling_limit", "number ≥ 0", "", "pair default", "the pair's η_r; at least one of `friction`, `kt_kn`, `rolling_stiffness`, `rolling_limit`, `model` or `rolling_law` is required", kRolling),
                     word("model", "`linear` \\| `hertz_mindlin`", {"linear", "hertz_mindlin"}, "the case's `contact_model`", "the pair's contact model; another name is an error listing the valid ones"),
                     word("rolling_law", "`incremental` \\| `total`", {"incremental", "total"}, "the two materials' law", "the pair's rolling law; see [rolling laws](#rolling-laws)"),
                 }));

    // ---------------------------------------------------------------- particles
    t.push_back(sec("particles",
                 {
                     map("inline", "mapping", "", "–", "spheres listed in the case, see [inline](#inline); each item has exactly one of `inline`, `generate`, `file`", "particles.inline"),
                     map("generate", "mapping", "", "–", "a random cloud of non-overlapping spheres, see [generate](#generate); each item has exactly one of `inline`, `generate`, `file`", "particles.generate"),
                     map("file", "mapping", "", "–", "spheres read from a text file, see [file](#file); each item has exactly one of `inline`, `generate`, `file`", "particles.file"),
                 }));
    t.push_back(sec("particles.inline",
                 {
                     str("material", "material name", "", "**required**", "a `materials` name: the material of every sphere of the entry"),
                     vec3("velocity", "`[vx, vy, vz]`", "m/s", "`[0, 0, 0]`", "initial velocity of every sphere of the entry", kVelocity),
                     // the list's entries [x, y, z, r] have the path particles.inline.spheres (range row of that name)
                     any("spheres", "list", "", "**required**, non-empty", "each `[x, y, z, r]` or `{id: 7, x: [x, y, z], r: r, v: [vx, vy, vz]}` (`id`, `v` optional; `v` overrides `velocity`)", kCoord, "particles.inline.spheres"),
                 }));
    // The mapping form of an inline sphere ({id, x, r, v}); the r of the list form [x, y, z, r] is
    // checked as particles.inline.spheres.r too.
    t.push_back(sec("particles.inline.spheres",
                 {
                     integer("id", "integer ≥ 0", "–", "none", "the particle's id (see [Particle ids](#particle-ids)); an `id` ≥ 0", kSeed),
                     vec3("x", "`[x, y, z]`", "m", "**required**", "centre; inside the domain", kCoord),
                     num("r", "number > 0", "m", "**required**", "radius; the radius must be > 0 (also the r of `[x, y, z, r]`)", R{1e-6, 10, '+', "m"}),
                     vec3("v", "`[vx, vy, vz]`", "m/s", "the entry's `velocity`", "initial velocity; `v` overrides `velocity`", kVelocity),
                 }));
    t.push_back(sec("particles.generate",
                 {
                     str("material", "material name", "", "**required**", "a `materials` name: the material of every sphere of the cloud"),
                     map("box", "`{min, max}`", "m", "**required**", "must lie inside the domain", "particles.generate.box"),
                     integer("count", "positive integer", "–", "–", "number of particles", R{1, 2147483647, '+', ""}),
                     num("porosity", "number in (0, 1)", "–", "–", "fill the box to this porosity", R{1e-6, 1, '+', ""}),
                     integer("seed", "integer ≥ 0", "–", "`1`", "random seed", kSeed),
                     integer("max_attempts", "positive integer", "–", "`100`", "placement attempts per particle", kMaxAttempts),
                     word("placement", "`sequential` or `cells`", {"sequential", "cells"}, "`sequential`", "`sequential`: one random sequential addition over the box, built by every rank; `cells`: the box cut into generation cells, each rank builds only its block (for large clouds; see below)"),
                     vec3("velocity", "`[vx, vy, vz]`", "m/s", "`[0, 0, 0]`", "initial velocity", kVelocity),
                     map("size", "mapping", "", "**required**", "[size distribution](#size-distributions)", "particles.generate.size"),
                 }));
    t.push_back(box("particles.generate.box"));
    t.push_back(size("particles.generate.size"));
    t.push_back(sec("particles.file",
                 {
                     str("path", "string", "", "**required**", "relative to the case file's directory"),
                     str("material", "material name", "", "**required**", "a `materials` name: the material of every sphere of the file"),
                     num("scale", "number > 0", "–", "`1`", "multiplies coordinates and radii", R{1e-6, 1e6, '+', ""}),
                     vec3("offset", "`[x, y, z]`", "m", "`[0, 0, 0]`", "added to the centres after scaling", kCoord),
                     vec3("velocity", "`[vx, vy, vz]`", "m/s", "`[0, 0, 0]`", "initial velocity (extension)", kVelocity),
                 }));

    // ---------------------------------------------------------------- walls
    {
      Section s;
      s.path = "walls";
      s.keys = {
          str("name", "string", "", "**required**", "unique"),
          word("type", "`plane`, `box`, `container` or `facets`", {"plane", "box", "container", "facets"}, "**required**", "the kind of wall: an infinite plane, a solid axis-aligned box (grains outside it), a [container](#containers) (grains inside: six planes facing in), or triangles"),
          str("material", "material name", "", "**required**", "a `materials` name: the wall side of every grain–wall contact"),
          any("motion", "see below", "", "`fixed`", "how the wall moves (the forms are listed below)", kNoRange, "walls.motion"),
          vec3("point", "`[x, y, z]`", "m", "**required**", "a point on the plane", kCoord),
          vec3("normal", "`[x, y, z]`", "–", "**required**", "normal (non-zero, normalised on reading) pointing to the particles' side", kDirection),
          vec3("min", "`[x, y, z]`", "m", "**required**", "box: a solid axis-aligned box, `min < max`; particles touch its faces, edges, corners from outside. container: the inside's lower corner", kCoord),
          vec3("max", "`[x, y, z]`", "m", "**required**", "the upper corner, `min < max`", kCoord),
          strings("open", "list of `xmin`, `xmax`, `ymin`, `ymax`, `zmin`, `zmax`", "none (closed)", "a container's faces left out, e.g. `[zmax]` for an open top"),
          numbers("segments", "`[n1, n2]`, each 1–1000", "–", "none", "a servo box cut across its axis into n1 × n2 equal boxes, each its own servo: a [loading plate that follows the surface](#segmented-servo-plates)"),
          any("vertices", "list of `[x, y, z]`", "m", "**required**", "the corners of the triangles (facets)", kCoord),
          any("triangles", "list of `[i, j, k]`", "–", "**required**, non-empty", "0-based vertex indices; zero-area triangles are rejected", R{1, 2147483647, '0', ""}),
          map("bands", "`{axis, edges}`", "", "none", "the force on the wall also per band: its contacts summed by where the grain's centre lies along `axis`, between consecutive `edges` (pressure against depth on a retaining wall or a shaft), see [force bands](#force-bands)", "walls.bands"),
      };
      s.variant_key = "type";
      s.variants = {{"plane", {"name", "type", "material", "motion", "point", "normal", "bands"}},
                    {"box", {"name", "type", "material", "motion", "min", "max", "segments", "bands"}},
                    {"container", {"name", "type", "material", "min", "max", "open"}},
                    {"facets", {"name", "type", "material", "motion", "vertices", "triangles", "bands"}}};
      t.push_back(std::move(s));
    }
    t.push_back(sec("walls.bands",
                 {
                     vec3("axis", "`[x, y, z]`", "–", "**required**", "the direction along which the bands lie (non-zero, normalised on reading), e.g. `[0, 0, 1]` for depth bands", kDirection),
                     numbers("edges", "list of ≥ 2 numbers, strictly increasing", "m", "**required**", "band k holds the contacts whose grain centre c has edges[k] ≤ c · axis < edges[k+1]; contacts outside every band count only in the wall's total", kCoord),
                 }));
    {
      // `motion`: the word `fixed`, one motion {velocity | free | servo} (variant "single") or a
      // schedule, a list of phases (variant "phase"; the reader's path is walls[i].motion[k], so
      // walls.motion too).
      Section s;
      s.path = "walls.motion";
      s.keys = {
          integer("from_step", "integer ≥ 0", "–", "`0` (first phase)", "a phase of a [motion schedule](#motion-schedules) only: the phase applies from step N (the first phase's `from_step` defaults to 0; before it the wall is fixed); steps must strictly increase", R{1, 1e12, '0', ""}),
          str("name", "string", "", "none", "a phase of a [motion schedule](#motion-schedules) only: its name, for another phase's `after: {stage: name}`"),
          map("after", "`{unbalanced, kinetic_ratio, servo, time, steps, stage}`", "", "–", "a phase of a [motion schedule](#motion-schedules) only, instead of `from_step`: the phase starts at the first history row where every condition given holds ([phases that start on a condition](#phases-that-start-on-a-condition)); the phases after it start `after:` a condition too", "walls.motion.after"),
          boolean("fixed", "`true`", "–", "a phase of a [motion schedule](#motion-schedules) only: `fixed: true`, the wall does not move (only `fixed: true` is meaningful)"),
          vec3("velocity", "`[vx, vy, vz]`", "m/s", "–", "moves with this constant velocity (m/s)", kVelocity),
          map("free", "`{mass: m, dofs: [x, y, z], gravity: false, velocity: [vx, vy, vz]}`", "", "–", "moves under the particles' forces", "walls.motion.free"),
          map("servo", "`{stress: σ0, max_velocity: v, …}`", "", "–", "stress-controlled (servo) wall, see [servo walls](#servo-walls)", "walls.motion.servo"),
      };
      s.variants = {{"single", {"velocity", "free", "servo"}},
                    {"phase", {"from_step", "after", "name", "fixed", "velocity", "free", "servo"}}};
      t.push_back(std::move(s));
    }
    t.push_back(sec("walls.motion.after",
                 {
                     num("unbalanced", "number > 0", "–", "none (not checked)", "the unbalanced-force ratio (history.csv's) below this, with a contact", R{1e-12, 1e3, '+', ""}),
                     num("kinetic_ratio", "number ≥ 0", "–", "`0.001`", "with `unbalanced`: the grains' kinetic energy per grain also below this times m̄·g·d̄ (nothing still falling; as `time.stop_kinetic_ratio`); 0 = not checked", R{1e-12, 1e6, '0', ""}),
                     num("servo", "number > 0", "–", "none (not checked)", "every servo wall's misfit, the size of (σ − σ0) / σ0, below this (the plates have found their stress)", R{1e-12, 1e3, '+', ""}),
                     num("time", "number > 0", "s", "none (not checked)", "at least this long after the previous phase began (the run's start for the first phase)", R{1e-12, 1e9, '+', "s"}),
                     integer("steps", "integer > 0", "steps", "none (not checked)", "at least this many steps after the previous phase began", R{1, 1e12, '+', ""}),
                     str("stage", "phase name", "", "none", "starts at the step the phase of this `name` starts (any wall's): walls that move together share one condition; no other condition with it"),
                 }));
    t.push_back(sec("walls.motion.free",
                 {
                     num("mass", "number > 0", "kg", "**required**", "the wall's mass", R{1e-12, 1e12, '+', "kg"}),
                     strings("dofs", "list of `x`, `y`, `z`", "all of x, y, z", "the free translations", kDofs3),
                     boolean("gravity", "bool", "`false`", "whether gravity acts on it"),
                     vec3("velocity", "`[vx, vy, vz]`", "m/s", "`0`", "initial velocity", kVelocity),
                 }));
    t.push_back(sec("walls.motion.servo",
                 {
                     num("stress", "number ≥ 0", "Pa", "**required**", "σ0, compression positive (tension is not allowed)", R{1e-6, 1e10, '0', "Pa"}),
                     vec3("axis", "`[x, y, z]`", "–", "planes: the normal; **required** for box and facets", "direction in which the wall compresses the specimen (normalised)", kDirection),
                     any("area", "number > 0, `auto` or `{between: [[a, b], [c, d]]}`", "m²", "box/facets: `auto`; **required** for planes", "A. `auto`: a box's face across the axis, or the facets' area projected across the axis (a flat plate counts once; give `area` for closed meshes). `between`: the product of the current gaps between plane walls a–b and c–d (a triaxial cell's lateral walls)", kArea, "walls.motion.servo.area"),
                     num("gain", "number in (0, 1]", "–", "`0.5`", "fraction of the force error corrected per step (YADE's `wallDamping`); > 1 can overshoot and is refused", R{1e-9, 1, '+', ""}),
                     any("stiffness", "number > 0 or `auto`", "N/m", "`auto`", "a fixed K used while the wall has contacts, instead of the contacts' sum (a softer servo: larger K)", R{1e-6, 1e15, '+', "N/m"}),
                     num("max_velocity", "number > 0", "m/s", "**required**", "cap on the wall's speed along its axis (and the approach speed without contacts)", R{1e-12, 1e4, '+', "m/s"}),
                     vec3("velocity", "`[vx, vy, vz]`", "m/s", "`[0, 0, 0]`", "prescribed velocity across the axis (its axis component is ignored): e.g. the top plate of a shear box moving with the upper half", kVelocity),
                 }));
    t.push_back(sec("walls.motion.servo.area",
                 {
                     any("between", "`[[a, b], [c, d]]`", "", "**required**", "two pairs of plane wall names: A is the product of the current gaps between plane walls a–b and c–d (a triaxial cell's lateral walls)"),
                 }));

    // ---------------------------------------------------------------- constraints
    t.push_back(sec("constraints",
                 {
                     numbers("ids", "list of integers", "–", "–", "particle ids", R{1, 9e15, '0', ""}),
                     map("region", "`{min, max}`", "m", "–", "particles whose centre is in the box at the start", "constraints.region"),
                     boolean("fixed", "bool", "false", "`true` blocks all six dofs with zero velocity"),
                     strings("block", "list of `x, y, z, rx, ry, rz`", "–", "the blocked dofs", kDofs6),
                     vec3("velocity", "`[vx, vy, vz]`", "m/s", "none", "prescribed velocity of the blocked translations (not with `fixed: true`)", kVelocity),
                 }));
    t.push_back(box("constraints.region"));

    // ---------------------------------------------------------------- output, progress, neighbor, restart
    t.push_back(sec("output",
                 {
                     str("dir", "string", "", "`out/<name>`", "output directory (relative to the working directory); `--out` on the command line overrides"),
                     integer("snapshot_every", "integer ≥ 0", "steps", "`0`", "particle snapshots; 0 = first and last step only", R{1, 1e12, '0', "steps"}),
                     integer("history_every", "integer > 0", "steps", "`100`", "history (CSV) lines", R{1, 1e12, '+', "steps"}),
                     integer("checkpoint_every", "integer ≥ 0", "steps", "`0`", "checkpoints; 0 = only at the end and on a signal", R{1, 1e12, '0', "steps"}),
                 }));
    t.push_back(sec("progress",
                 {
                     num("interval", "number > 0", "s", "`5`", "seconds between progress lines", R{1e-3, 1e6, '+', "s"}),
                 }));
    t.push_back(sec("neighbor",
                 {
                     any("skin", "positive number or `auto`", "m", "`auto`", "Verlet-list skin: a positive length (m) or `auto` = 0.3 × the largest radius. Lists are rebuilt when a particle has moved more than skin/2 (global check every step); the ghost layer is 2·r_max + skin wide", R{1e-9, 10, '+', "m"}),
                 }));
    t.push_back(sec("decomposition",
                 {
                     any("grid", "`auto` or `[px, py, pz]`", "ranks", "`auto`", "the process grid: px × py × pz subdomains along x, y, z (LAMMPS's `processors`), their product the number of ranks (else exit 2). `auto`: the smallest total area of cut planes for the domain box among the grids that do not cut across gravity (grains under gravity end on the floor: a cut across gravity has to chase them, a cut along it stays balanced), or among all grids if none fits; every subdomain at least one ghost layer (2·r_max + skin) wide. Cut planes then move with the load. Results are the same for any grid"),
                 }));
    t.push_back(sec("restart",
                 {
                     str("from", "path", "", "**required**", "continue from this checkpoint; the path is relative to the case file's directory (`--restart FILE` on the command line does the same, relative to the working directory). With `restart`, `particles` may be omitted (the particles come from the checkpoint)"),
                 }));

    // ---------------------------------------------------------------- fem
    t.push_back(sec("fem",
                 {
                     word("solver", "`relaxation` or `static`", {"relaxation", "static"}, "`relaxation`", "explicit dynamic relaxation, or the linear static solve with PETSc KSP (elastic materials only; `restraints` must fix some node in every direction, else an input error): one solve per hold, counted as one step (hold k ends at step k; see the output below)"),
                     any("damping", "positive number or `auto`", "1/s", "`auto`", "mass-proportional damping c; `auto` = adaptive, c = 2·sqrt(Δu·ΔF / Δu·M·Δu) each step (the lowest mode's critical damping)", R{1e-12, 1e12, '+', "1/s"}),
                     num("safety", "number in (0, 1]", "–", "`0.8`", "dt = safety × 2/sqrt(λ_max), λ_max from the Gershgorin bound max_i Σ_j abs(K_ij) / M_ii", R{1e-6, 1, '+', ""}),
                     any("mass_scaling", "number ≥ 1 or `auto`", "–", "`1`", "every FE density is multiplied by it (the lumped masses, hence the stable step × sqrt(mass_scaling)); the body load (`unit_weight`) is not. Dynamic relaxation seeks the static state, which does not depend on the mass: a thin stiff structure (a 0.9 mm geogrid) coupled to soil can then step with the DEM instead of forcing a DEM step tens of times smaller. Keep the structure's scaled mass below the soil's around it and ramp the loads (`coupling.ramp_steps`); the holds' convergence check includes the structure's global equilibrium, so the answer is static. `auto` (coupled cases): the smallest scaling (≥ 1) at which the FE stable step with the interface contact stiffness (× `safety`) is the DEM's own step, s = (dt_DEM / dt_FE,stable(s = 1))², so the structure neither clamps the DEM step nor carries more mass than that needs; chosen once from the grains the run starts with (a restart keeps the checkpoint's), printed at the start and in `run.json` (`coupling.mass_scaling`)", R{1e-6, 1e12, '+', ""}),
                     num("tolerance", "number > 0", "–", "`1e-4`", "a hold ends when the unbalanced-force ratio ‖R_free‖ / max(‖P + B‖, ‖reactions‖) is below it; with several `meshes` the ratio of each mesh, against its own loads and reactions, and the largest counts (a rigid part's reactions do not hide another part's residual)", R{1e-30, 1, '+', ""}),
                     integer("max_steps", "integer > 0", "steps", "`1000000`", "per hold; a hold that does not converge is reported and the run goes on", R{1, 1e12, '+', ""}),
                     integer("check_every", "integer > 0", "steps", "`100`", "steps between convergence checks (and progress/signal polls)", R{1, 1e9, '+', "steps"}),
                     boolean("gravity", "bool", "`false`", "body load: each material's `unit_weight` along the case's `gravity` direction"),
                     boolean("distribute", "bool", "`false`", "the mesh in parts: rank 0 builds or reads it, partitions it and sends each rank its elements and their nodes; the other ranks never hold the whole mesh (for FE meshes too large to replicate, docs/performance.md \"FE mesh memory\"). Results equal the replicated run's bit for bit (`solver: static`: within the KSP error bound). With `coupling`, rank 0 also makes the interface and sends every rank its triangles and nodes (the interface is on every rank, the mesh is not)"),
                     list("materials", "list", "", "**required**", "see below", "fem.materials"),
                     list("meshes", "list", "", "**required**", "see below", "fem.meshes"),
                     list("restraints", "list", "", "none", "boundary conditions, see below", "fem.restraints"),
                     list("loads", "list", "", "none", "boundary conditions, see below", "fem.loads"),
                     list("displacements", "list", "", "none", "boundary conditions, see below", "fem.displacements"),
                     conditional(numbers("load_steps", "list of numbers", "–", "`[1]`", "load factor per hold: loads are `factor × P`", R{1e-12, 1e6, '~', ""})),
                     conditional(numbers("displacement_steps", "list of numbers", "–", "`[1]`", "displacement factor per hold: prescribed displacements are `factor × U` (same length as `load_steps` when both are given)", R{1e-12, 1e6, '~', ""})),
                     list("ties", "list of `{mesh, to, node_set, tolerance}`", "", "none", "tie meshes at coincident nodes: each node of `mesh` (or of its `node_set`) within `tolerance` of a node of `to` becomes that node, so the two share it (a pipe's shells in the soil's cut-out; `cases/fem/tied_blocks.yaml`); the start-up line gives the count. A tied node keeps its row in the output, with the values of the node it became", "fem.ties"),
                     list("remove", "list of `{mesh, element_set, at_hold}`", "", "none", "remove the elements of a set at the start of a hold (0-based), e.g. the formation under a void (thesis ch. 6, `cases/void/`); their weight goes with them, and nodes left in no element are held still. In a coupled run the interface follows: the removed elements' faces leave it and the faces they shared with remaining elements (the void's walls) join it, at once (interface triangles of every hold's surface are made at the start; `coupling.surfaces` of the whole mesh or of an element set); the start-up and hold lines give the triangle counts", "fem.remove"),
                 }));
    t.push_back(sec("fem.materials",
                 {
                     str("name", "string", "", "**required**", "the material's name, used by `fem.meshes[].material` (unique)"),
                     word("model", "`elastic` or `mohr_coulomb`", {"elastic", "mohr_coulomb"}, "`elastic`", "Mohr–Coulomb: perfectly plastic, closest-point return at the Gauss points"),
                     num("young", "number > 0", "Pa", "**required**", "E", R{1e3, 1e13, '+', "Pa"}),
                     num("poisson", "number in (−1, 0.5)", "–", "`0`", "ν", R{1e-9, 1, '~', ""}),
                     num("density", "number > 0", "kg/m³", "**required**", "lumped mass", R{1, 1e5, '+', "kg/m^3"}),
                     num("unit_weight", "number ≥ 0", "N/m³", "`0`", "γ, body load when `fem.gravity: true`", R{1e-6, 1e6, '0', "N/m^3"}),
                     conditional(num("cohesion", "number ≥ 0", "Pa", "`0`", "c (mohr_coulomb)", R{1e-6, 1e10, '0', "Pa"})),
                     num("friction_angle", "number in [0, 90)", "degrees", "**required** (mohr_coulomb)", "φ", R{1e-9, 90, '0', "degrees"}),
                     conditional(num("dilation_angle", "number in [0, φ]", "degrees", "`0`", "ψ", R{1e-9, 90, '0', "degrees"})),
                     num("hourglass", "number ≥ 0", "–", "`0.05`", "hex8r hourglass stiffness factor", R{1e-12, 1, '0', ""}),
                     num("thickness", "number > 0", "m", "–", "shell thickness; **required** for a material used by shell4 meshes", R{1e-6, 10, '+', "m"}),
                     boolean("nlgeom", "bool", "`false`", "geometrically nonlinear, as Abaqus's NLGEOM: total Lagrangian with Green–Lagrange strain and a St Venant–Kirchhoff law, so a rigid rotation makes no stress and a sagging membrane stretches (a geogrid over a void, `cases/fem/membrane_strip.yaml`). Elastic hex8, hex8i, hex20 and quad4 only (not hex8r, shell4, mohr_coulomb or `solver: static`); the output's stress is Cauchy, its strain Green–Lagrange. On `hex8i` it is corotational instead (each brick's rotation, the polar factor of F at its centre, taken out; small strain in the rotated frame; output stress and strain turned back)"),
                 }));
    t.push_back(sec("fem.meshes",
                 {
                     str("name", "string", "", "**required**", "unique"),
                     str("material", "string", "", "**required**", "an `fem.materials` name"),
                     map("block", "mapping", "", "–", "a structured block of bricks; node sets `xmin`, `xmax`, `ymin`, `ymax`, `zmin`, `zmax`. Exactly one of `block`, `geogrid`, `thesis`, `gmsh`, `cylinder`", "fem.meshes.block"),
                     map("geogrid", "mapping", "", "–", "a generated biaxial geogrid; sets: see docs/mesh-formats.md. Exactly one of `block`, `geogrid`, `thesis`, `gmsh`, `cylinder`", "fem.meshes.geogrid"),
                     map("thesis", "mapping", "", "–", "the thesis's text formats (appendix A.3.3.2; shells as in `load_shell_elements`, thickness from the material). Exactly one of `block`, `geogrid`, `thesis`, `gmsh`, `cylinder`", "fem.meshes.thesis"),
                     str("gmsh", "path", "", "–", "a Gmsh .msh 4.1 ASCII file; physical groups become element and node sets. Exactly one of `block`, `geogrid`, `thesis`, `gmsh`, `cylinder`"),
                     map("cylinder", "mapping", "", "–", "a pipe of shell4 elements along +`axis` (default z); element normals point outwards; node sets `start`, `end`, element set `all`. Exactly one of `block`, `geogrid`, `thesis`, `gmsh`, `cylinder`", "fem.meshes.cylinder"),
                 }));
    t.push_back(sec("fem.meshes.block",
                 {
                     vec3("min", "`[x, y, z]`", "m", "**required**", "the block's lower corner", kCoord),
                     vec3("max", "`[x, y, z]`", "m", "**required**", "the block's upper corner; `min < max` in every direction (shell4: equal in the plate's direction)", kCoord),
                     numbers("divisions", "`[nx, ny, nz]`", "–", "**required**", "elements along x, y, z (positive integers; shell4: 1 across the plate)", R{1, 1e6, '+', ""}),
                     word("element", "`hex8`, `hex8i`, `hex8r` or `shell4`", {"hex8", "hex8i", "hex8r", "shell4"}, "`hex8`", "the element type (`hex8i`: with incompatible modes, bends without locking); `shell4`: a flat plate of shells where `min` and `max` are equal in one direction (e.g. `min.z = max.z`), normals along + that direction, element set `all`, node sets of its four edges (thickness from the material)"),
                     map("void", "`{min, max}`", "m", "none", "the elements whose centres are inside form the element set `void`; they stay in the mesh until a `remove`", "fem.meshes.block.void"),
                 }));
    t.push_back(box("fem.meshes.block.void"));
    t.push_back(sec("fem.meshes.geogrid",
                 {
                     num("length", "number > 0", "m", "**required**", "overall size along x (clamp included)", kGeogridLength),
                     num("width", "number > 0", "m", "**required**", "overall size along y (both side overhangs included)", kGeogridLength),
                     integer("longitudinal_ribs", "integer ≥ 2", "–", "**required**", "n_l: ribs along x, counted across the width", R{1, 1e4, '+', ""}),
                     integer("transverse_ribs", "integer ≥ 2", "–", "**required**", "n_t: ribs along y, counted along the length", R{1, 1e4, '+', ""}),
                     num("rib_width", "number > 0", "m", "**required**", "w: width of both rib families", kGeogridLength),
                     num("thickness", "number > 0", "m", "**required**", "t: rib thickness", kGeogridLength),
                     num("junction_thickness", "number ≥ 0", "m", "`0`", "t_j: 0: = t (the thesis's choice); else ≥ t, junctions symmetric about the ribs' mid-plane", kGeogridLength),
                     num("clamp_length", "number ≥ 0", "m", "`0`", "c: solid strip x ∈ [origin.x, origin.x + c] across the full width (0: none); thickness t", kGeogridLength),
                     num("clamp_gap", "number ≥ 0", "m", "one aperture", "g: clear distance from the clamp to the first transverse rib (default: one aperture a_x with a clamp, 0 without)", kGeogridLength),
                     num("side_overhang", "number ≥ 0", "m", "`0`", "o: the transverse ribs and the clamp run on this far beyond the outermost longitudinal ribs on both sides, `width` included; half an aperture for a slice between symmetry planes through the apertures, restrain its node sets `ymin`/`ymax` in y", kGeogridLength),
                     vec3("origin", "`[x, y, z]`", "m", "`[0, 0, 0]`", "the grid's minimum corner", R{1e-300, 1e5, '~', "m"}),
                     integer("elements_per_rib_width", "positive integer", "–", "`1`", "elements across a rib (and along a rib inside a junction)", R{1, 1000, '+', ""}),
                     integer("elements_through_thickness", "positive integer", "–", "`1`", "element layers through t (thicker junctions: one more layer above and below)", R{1, 1000, '+', ""}),
                     num("max_element_length", "number ≥ 0", "m", "`0`", "h: longest element along a rib (apertures, clamp gap, clamp); 0: h = w", kGeogridLength),
                     word("element", "`hex8` or `hex8i`", {"hex8", "hex8i"}, "`hex8`", "the bricks: `hex8` (the thesis's, 2×2×2 points) locks in bending with one brick through a rib's thickness (a rib over 0.2 m ~34 times too stiff: docs/cases/void.md); `hex8i` (incompatible modes, as Abaqus's C3D8I) bends as a beam with one"),
                 }));
    t.push_back(sec("fem.meshes.thesis",
                 {
                     str("nodes", "path", "", "**required**", "the node file (`id x y (z)`), relative to the case file"),
                     str("elements", "path", "", "**required**", "the element file (`id n1 n2 ...`), relative to the case file"),
                     word("element", "`hex8`, `hex8i`, `hex8r`, `hex20`, `quad4` or `shell4`", {"hex8", "hex8i", "hex8r", "hex20", "quad4", "shell4"}, "`hex8`", "the element type"),
                     conditional(integer("dim", "2 or 3", "–", "`3`", "2 for quad4", R{2, 3, '+', ""})),
                 }));
    t.push_back(sec("fem.meshes.cylinder",
                 {
                     vec3("base", "`[x, y, z]`", "m", "`[0, 0, 0]`", "axis point of the first ring", kCoord),
                     num("radius", "number > 0", "m", "**required**", "the pipe's radius", R{1e-6, 1e3, '+', "m"}),
                     num("length", "number > 0", "m", "**required**", "the pipe's length along +`axis`", R{1e-6, 1e3, '+', "m"}),
                     word("axis", "`x`, `y` or `z`", {"x", "y", "z"}, "`z`", "the pipe's axis; ring node i at angle 2πi/around from the next axis towards the one after (z: from x towards y; y: from z towards x; x: from y towards z)"),
                     numbers("divisions", "`[around, along]`", "–", "**required**", "elements around (at least 3) and along the pipe", R{1, 1e6, '+', ""}),
                 }));
    t.push_back(nodal("fem.restraints", "a thesis-format file (node ids of that mesh): `id rx ry rz`, 1 = fixed translation",
                      strings("fixed", "list of `x, y, z, rx, ry, rz`", "**required** with `node_set` or `region`", "the listed dofs are held at zero (any subset; rotations only matter for shell nodes)", kDofs6)));
    t.push_back(box("fem.restraints.region"));
    {
      Section s = nodal("fem.loads", "a thesis-format file (node ids of that mesh): `id fx fy fz` per node",
                        vec3("total", "`[Fx, Fy, Fz]`", "N", "**required** with `node_set` or `region`", "reference load P, split equally over the set's nodes, scaled by `load_steps`", R{1e-12, 1e12, '~', "N"}));
      s.keys.push_back(num("pressure", "number", "Pa", "–", "`{mesh, pressure: p}`: on every shell4 element of the mesh along its normal: p·A·n/4 per node, scaled by `load_steps`", R{1e-12, 1e12, '~', "Pa"}));
      s.variants = {{"nodal", {"mesh", "node_set", "region", "file", "total"}}, {"pressure", {"mesh", "pressure"}}};
      t.push_back(std::move(s));
    }
    t.push_back(box("fem.loads.region"));
    t.push_back(nodal("fem.displacements", "a thesis-format file (node ids of that mesh): `id ux uy uz`",
                      vec3("value", "`[ux, uy, uz]`", "m", "**required** with `node_set` or `region`", "every node of the set; all three dofs of these nodes are prescribed: `factor × U`, scaled by `displacement_steps`", R{1e-15, 1e3, '~', "m"})));
    t.push_back(box("fem.displacements.region"));
    t.push_back(sec("fem.remove",
                 {
                     str("mesh", "string", "", "**required**", "an `fem.meshes` name"),
                     str("element_set", "string", "", "**required**", "an element set of that mesh"),
                     integer("at_hold", "integer ≥ 0", "–", "**required**", "the hold (0-based) at whose start the elements are removed", R{1, 1e9, '0', ""}),
                 }));
    t.push_back(sec("fem.ties",
                 {
                     str("mesh", "string", "", "**required**", "the `fem.meshes` name whose nodes are tied (each mesh at most once)"),
                     str("to", "string", "", "**required**", "the mesh they are tied to (another one; a mesh tied in its turn passes its nodes on)"),
                     str("node_set", "string", "", "all nodes", "only this node set of `mesh`"),
                     num("tolerance", "number > 0", "m", "`1e-9`", "largest distance between two nodes that become one; a tie that joins no node is an input error", R{1e-15, 1e3, '+', "m"}),
                 }));

    // ---------------------------------------------------------------- coupling
    t.push_back(sec("coupling",
                 {
                     str("material", "string", "", "**required**", "name of a DEM material (`materials:`) used for the interface triangles: the particle–interface contacts use the DEM contact law with it (stiffness from its `young`, friction from `friction` or an `interactions` pair)"),
                     list("surfaces", "list", "", "**required**, non-empty", "the FE surfaces that carry interface triangles, see below; the triangles of all entries are used together", "coupling.surfaces"),
                     integer("subcycle", "integer ≥ 0", "DEM steps", "`0`", "the FE takes one step every n DEM steps (dt_FE = n·dt_DEM); `0` = automatic, n = floor(dt_FE,stable / dt_DEM). dt_FE,stable = `fem.safety` × the Gershgorin step of the structure **with the interface contact stiffness** on every interface node (one contact of the stiffest particle against `material`, or on coarse elements a dense layer of the grains over the node's share of the surface), see the user guide, \"Coupled runs\". A given n with n·dt_DEM above dt_FE,stable is an error (exit 2) that names the largest stable n", R{1, 1e6, '0', ""}),
                     integer("rigid_steps", "integer ≥ 0", "DEM steps", "`0`", "the structure is held rigid (not stepped; interface forces are still reduced and reported) for the first `rigid_steps` DEM steps, then released", R{1, 1e12, '0', "steps"}),
                     num("tolerance", "number > 0", "–", "`fem.tolerance`", "a hold (`fem.load_steps` / `displacement_steps`) ends when all of these are below it: the DEM unbalanced-force ratio, the FE unbalanced-force ratio (norm), the FE **resultant** ratio \\|Σ R_free\\| / max(Σ_nodes \\|F_ext\\|, \\|Σ reactions\\|) (the structure in global equilibrium: e.g. a clamp force equal to the soil's pull on the grid; a residual spread over many nodes hides in the norm); both FE ratios per case mesh, the largest counting, and the servo misfit max \\|σ − σ₀\\|/σ₀ of the servo walls. `interface.csv` has all of them (`fe_unbalanced`, `fe_resultant`, `dem_unbalanced`, `servo_misfit`)", R{1e-30, 1, '+', ""}),
                     num("kinetic_ratio", "number > 0", "–", "none (not checked)", "a hold also needs the grains' kinetic energy per grain (translational and rotational) below this times m̄·g·d̄ (the mean grain mass and diameter at the start): nothing still falling. The unbalanced-force ratio is a mean over all grains and does not see a few grains in free fall (a void opened under a fill: thesis ch. 6); `packing.settle.kinetic_ratio` is the same test", R{1e-12, 1e6, '+', ""}),
                     num("grain_resultant", "number > 0", "–", "none (not checked)", "a hold also needs the grains' resultant ratio \\|Σ_i (f_i + m_i g)\\| / Σ_i m_i\\|g\\| below this (f_i a grain's contact, wall and interface forces; the acceleration of the grains' centre of mass in g): the fill balanced as a whole. The unbalanced-force ratio is a mean of each grain's own imbalance and does not see a column ringing after a release (a void opened under a fill: its supports' force swinging ±10 % about the weight while each grain is nearly balanced). Measured against the grains' weight: meant for fills loaded by gravity, not for specimens whose walls carry loads many times their weight. `holds.csv` has it at every hold's end (`grain_resultant`) whether checked or not", R{1e-12, 1e3, '+', ""}),
                     num("creep", "number > 0", "m", "none (not checked)", "an FE part (each case mesh) whose unbalanced ratio (norm) does not fall below `tolerance` still counts as converged when it is balanced as a whole (its resultant ratio below `tolerance`) and at rest: its drift since the previous check (`check_every` DEM steps earlier; a hold's first check counts from its start), the mass-weighted RMS displacement of its nodes, is below this length. A mass-scaled grid in soil (`fem.mass_scaling`) at rest keeps a norm of a few per cent from a few nodes chattering against the grains (a thin rib twisting) about their places, which no damping removes: they have a speed but no drift. The resultant still has to balance, so a grid held up by an over-damped creep does not count; `holds.creep` is the same test for the held walls. `holds.csv` has each part's ratios, RMS speed and drift and names the parts that held each hold open (`held_by`)", R{1e-15, 1, '+', "m"}),
                     num("creep_damping", "number > 0", "–", "none (`fem.damping` throughout)", "at every check of a hold the FE damping becomes this fraction of the largest damping with which a part creeping at `creep` per check interval still balances as a whole, c = tolerance·ΣF / (M·v_c) (ΣF the sum over the part's nodes of their loads' magnitudes, M its scaled mass, v_c = `creep` / the check interval; the least over the parts that move), never more than `fem.damping` (the damping before the first check). A damping force c·M·v larger than the resultant tolerance holds a creeping part out of balance, and the bound grows with the load: a fixed damping good at the working loads over-damps a seating hold at 1 kPa ([strip footing](cases/strip_footing.md#the-holds)). Needs `creep` and a fixed `fem.damping`; the damping used is in interface.csv (`fe_damping`)", R{1e-6, 1e3, '+', ""}),
                     integer("ramp_steps", "integer ≥ 0", "DEM steps", "`0`", "each hold's load and displacement factors move from the previous hold's (0 before the first) to its own over this many DEM steps, smoothly (½(1 − cos πt): no jump in velocity), instead of jumping at the hold's first FE step: a clamp pulled at a rate, then held (thesis 4.4). The convergence check starts after the ramp. With `rigid_steps`, the first hold starts at the release", R{1, 1e12, '0', "steps"}),
                 }));
    t.push_back(sec("coupling.surfaces",
                 {
                     str("name", "string", "", "the face set or element set name, else the mesh name", "unique among the surfaces; with two or more surfaces `interface.csv` gets the columns `<name>_fx`, `<name>_fy`, `<name>_fz` (N): the force on each surface's triangles, summed like `fx`, `fy`, `fz`"),
                     str("mesh", "string", "", "**required**", "an `fem.meshes` name (a 3-D mesh)"),
                     str("face_set", "string", "", "–", "a face set of that mesh (block meshes: `xmin`, `xmax`, `ymin`, `ymax`, `zmin`, `zmax`; geogrids: `top`, `bottom`, `transverse_front`; Gmsh: surface physical groups)"),
                     str("element_set", "string", "", "–", "an element set of that mesh: the boundary faces of its bricks and the quads of its shell4 elements. With neither `face_set` nor `element_set`: the whole surface of the mesh (every boundary face of every brick and every shell4 element)"),
                     str("material", "material name", "", "`coupling.material`", "this surface's interface material (a DEM material; pairs with the grains as any material, `interactions` included): e.g. a geogrid at tan φ 0.42 and a footing or formation at their own friction in one run"),
                 }));

    // ---------------------------------------------------------------- measure
    t.push_back(sec("measure",
                 {
                     integer("every", "integer > 0", "steps", "**required**", "steps between measurements (also at step 0 and at the last step)", R{1, 1e12, '+', "steps"}),
                     list("boxes", "list of `{name, min, max}`", "m", "none", "measurement boxes (axis-aligned, half-open `[min, max)`); `name` optional (default `box<i>`), unique; `min < max` in every direction; a box must overlap the domain. One row per box per measurement in `measure.csv`", "measure.boxes"),
                     map("grid", "`{min, max, divisions: [nx, ny, nz]}`", "m", "none", "a regular grid of boxes (cells); fields per cell in `measure_<step>.h5` (`/grid`) and `measure_grid.xdmf`. Divisions positive, at most 10⁷ cells", "measure.grid"),
                     list("roses", "list of `{plane, bins}`", "", "none", "contact-orientation histograms over all particle–particle contacts: `plane` one of `xy`, `xz`, `yz` (the angle runs from the first axis towards the second), `bins` (default `36`, at most 3600) over [0°, 180°). Rows in `roses.csv`", "measure.roses"),
                     boolean("force_network", "boolean", "`false`", "contact force network segments (centre A – centre B, normal force, force vector) in `measure_<step>.h5` (`/force_network`) and `force_network.xdmf` (polylines)"),
                     boolean("particle_displacements", "boolean", "`false`", "per-particle id, position and displacement in `measure_<step>.h5` (`/particles`)"),
                     integer("displacement_from", "integer ≥ 0", "step", "initial positions", "the step whose positions are the reference of every displacement (boxes, grid, particles, and the `displacement` of the particle snapshots): at that step the reference is reset to the current positions. The reference is checkpointed, so restarts keep it", R{1, 1e12, '0', ""}),
                 }));
    t.push_back(sec("measure.boxes",
                 {
                     str("name", "string", "", "`box<i>`", "unique"),
                     vec3("min", "`[x, y, z]`", "m", "**required**", "the box's lower corner (inclusive)", kCoord),
                     vec3("max", "`[x, y, z]`", "m", "**required**", "the box's upper corner (exclusive); `min < max` in every direction; a box must overlap the domain", kCoord),
                 }));
    t.push_back(sec("measure.grid",
                 {
                     vec3("min", "`[x, y, z]`", "m", "**required**", "the grid's lower corner", kCoord),
                     vec3("max", "`[x, y, z]`", "m", "**required**", "the grid's upper corner; `min < max` in every direction; the grid must overlap the domain", kCoord),
                     numbers("divisions", "`[nx, ny, nz]`", "–", "**required**", "cells along x, y, z: positive, each at most 100000, at most 10⁷ cells", R{1, 1e5, '+', ""}),
                 }));
    t.push_back(sec("measure.roses",
                 {
                     word("plane", "`xy`, `xz` or `yz`", {"xy", "xz", "yz"}, "**required**", "the angle runs from the first axis towards the second"),
                     integer("bins", "integer > 0", "–", "`36`", "bins over [0°, 180°), at most 3600", R{1, 3600, '+', ""}),
                 }));

    // ---------------------------------------------------------------- lab
    t.push_back(sec("lab",
                 {
                     map("direct_shear", "`{shear_walls: [names], normal_wall: name, direction: [1, 0, 0], area: A}`", "", "–", "Columns: `shear_displacement` (m, of the first shear wall along the direction), `normal_displacement` (m, of the normal wall against its axis: + is dilation), `sigma_n` (Pa, −**F**·**a**/A), `tau` (Pa, −Σ**F**·**d**/A over the shear walls), `tau_over_sigma_n`. Exactly one of `direct_shear`, `triaxial`", "lab.direct_shear"),
                     map("triaxial", "`{walls: [xmin, xmax, ymin, ymax, bottom, top]}`", "", "–", "six plane walls. Columns: `eps_a` = (h0 − h)/h0, `eps_v` = (V0 − V)/V0 (compression positive; h, V from the current wall gaps, h0, V0 at the start of the run), `sigma_x`, `sigma_y`, `sigma_z` (Pa, mean of the two walls of a pair, on the current face areas), `q` = σ_z − (σ_x + σ_y)/2, `p` = (σ_x + σ_y + σ_z)/3, `lx`, `ly`, `h` (m). Exactly one of `direct_shear`, `triaxial`", "lab.triaxial"),
                 }));
    t.push_back(sec("lab.direct_shear",
                 {
                     strings("shear_walls", "list of wall names", "**required**", "the walls of the moving half (include the top plate when it moves with it)"),
                     str("normal_wall", "wall name", "", "**required**", "the servo plate (must be servo-controlled)"),
                     vec3("direction", "`[x, y, z]`", "–", "`[1, 0, 0]`", "the shear direction (default x)", kDirection),
                     num("area", "number > 0", "m²", "the normal wall's servo area", "the nominal cross-section", kArea),
                 }));
    t.push_back(sec("lab.triaxial",
                 {
                     strings("walls", "`[xmin, xmax, ymin, ymax, bottom, top]`", "**required**", "six different plane walls"),
                 }));

    // ---------------------------------------------------------------- packing
    t.push_back(sec("packing",
                 {
                     word("method", "`layers` or `expansion`", {"layers", "expansion"}, "`layers`", "multi-layer gravitational packing (the thesis's) or radius expansion (fast)"),
                     str("material", "material name", "", "**required**", "material of the packed grains"),
                     map("box", "`{min, max}`", "m", "**required**", "the container's inside (the walls' faces); inside the domain; each side ≥ 4 largest diameters", "packing.box"),
                     integer("layers", "integer 1…1000", "", "`1`", "`layers` only: number of layers of equal nominal height box_z/layers (each ≥ 2 largest diameters)", R{1, 1000, '+', ""}),
                     num("porosity", "number in [0.2, 0.9)", "–", "`0.39`", "target porosity of the specimen: layer k's cloud holds the solid volume that brings the specimen up to its nominal top z_min + k·H/layers to this porosity, (1 − n)·A·k·H/layers minus what is already there (so a layer that packs denser than the target is followed by a thicker one). Frictionless packing reaches about 0.36–0.37 (random close packing): see the user guide", R{1e-6, 1, '+', ""}),
                     map("size", "size distribution", "m", "**required**", "as in [generate](#size-distributions) (diameters; uniform, normal, sieve, scale)", "packing.size"),
                     integer("seed", "integer ≥ 0", "", "`1`", "layer k's cloud uses seed + k (expansion: seed)", kSeed),
                     num("friction", "number ≥ 0", "–", "`0`", "tan φ of **every** contact (particle–particle and particle–wall, pair overrides too) while packing; the case's frictions are restored afterwards", kFriction),
                     list("exclude", "list of `{point, axis, radius}`", "", "none", "keep-out cylinders (infinite): the clouds hold no grain that reaches into one -- the space of a shaft or a pile whose walls stand in the packing box (`cases/shaft/`); the layers' solid volumes still count the box's whole section. Only placement is kept out: grains that roll in later (over the top of a structure lower than the layers' overfill, or through a gap) stay, and the packer warns at its end with their count", "packing.exclude"),
                     word("wall_friction", "`packing` or `case`", {"packing", "case"}, "`packing`", "the friction of the grain–wall (and grain–structure) contacts while packing: `packing` the packing's `friction`; `case` the case's own (pairs with `interactions`), kept through packing -- a shaft's 0.2 and frictionless boundaries while the grains rain with friction (thesis ch. 3)"),
                     num("cloud_fraction", "number in (0, 0.3]", "–", "`0.2`", "solid fraction of a generated cloud (random sequential addition stops near 0.25–0.3); below 1 − porosity. Layer k's cloud fills the slab from the current surface up by solid/(A·cloud_fraction)", R{1e-6, 1, '+', ""}),
                     integer("max_attempts", "integer", "", "`1000`", "placement attempts per particle (as `generate.max_attempts`)", kMaxAttempts),
                     word("placement", "`sequential` or `cells`", {"sequential", "cells"}, "`sequential`", "how each cloud (each layer's, the expansion's, the surcharge's) is generated, as `generate.placement`: `sequential` one random sequential addition, built whole by every rank for a moment (each keeps its share); `cells` in generation cells, each rank building only its block, so that no rank holds a whole layer's cloud (for specimens of millions of grains). Both give the same specimen on any number of ranks; they are different clouds, so different specimens"),
                     map("shaking", "mapping", "", "none", "lateral shaking of the box from the start of every layer: the named walls move together with velocity a·2πf·cos(2πf t)·direction (displacement a·sin 2πf t), for `cycles` periods (they end where they started)", "packing.shaking"),
                     map("settle", "mapping", "", "", "when a layer counts as settled: the `settle.*` keys", "packing.settle"),
                     map("expansion", "`{stages, stage_steps}`", "", "`{stages: 40, stage_steps: 200}`", "`expansion` only: the cloud is generated with its diameters shrunk to cloud_fraction in the whole box and grown to full size in `stages` equal factors with `stage_steps` steps of relaxation each, then settled as a layer (`settle`)", "packing.expansion"),
                     integer("final_steps", "integer ≥ 0", "steps", "`0`", "steps with the case's friction restored, after the last layer, before the report", R{1, 1e12, '0', "steps"}),
                     boolean("level", "bool", "`false`", "strike the specimen off level: after the last layer (before `final_steps`), the grains whose centre lies above the box's top are removed, so that the surface is at `box.max` z whatever porosity the layers reached (a structure placed at a depth below the surface, e.g. a geogrid 25 mm under a footing, is then at that depth). Set `porosity` at or below what the layers reach, so that they overfill the box; the report prints how many grains went"),
                     map("report", "`{margin, top_margin}`", "m", "2 d_max, 3 d_max", "the interior box of the report: inset `margin` from the box's sides and bottom and `top_margin` below the specimen's surface (the highest grain top)", "packing.report"),
                     conditional(integer("insert_structure_after_layer", "integer ≥ 0, < `layers`", "–", "`0`", "coupled cases only (`fem` + `coupling`): the structure (its interface surfaces as a rigid facet wall, its elements as solid) joins the packing after this layer (`0`: from the start; method `expansion`: always from the start); grains overlapping it are removed then and from later clouds; it is dropped at the end of packing and the coupled run takes over (user-guide.md#making-specimens). In a case without `fem` it is an error", R{1, 1000, '+', ""})),
                     list("structures", "list of `{mesh, after_layer}`", "", "none", "coupled cases only: per mesh, the layer after which its interface triangles join the packing (`0`: from the start), instead of `insert_structure_after_layer` -- a formation present from the first layer and a geogrid laid after the 0.1 m layer (thesis ch. 6). Meshes not listed join after `insert_structure_after_layer`; each mesh at most once", "packing.structures"),
                     map("surcharge", "`{material, thickness}`", "", "none", "a surcharge layer rained on the finished specimen (after `level`, before `final_steps`): grains of the packing's sizes in another material, `thickness` thick at the packing's porosity, settled as a layer -- a dense material standing for a uniform pressure γ_s(1 − n)·thickness (thesis ch. 6: 5 kPa over 0.05 m). `packing.json` gives its grains and the pressure they exert (their weight over the box's section); the report's interior box stays below it", "packing.surcharge"),
                     str("save", "path", "", "none", "also write the sphere text file here (relative to the case file)"),
                     strings("place_on_surface", "list of wall names", "none", "after packing (or after loading a specimen with `--specimen`), move each listed plane wall along its normal, and each listed servo box (axis along x, y or z) along its servo axis, until it touches the specimen's outermost grain (for a box: among the grains within a radius of its face): a servo top plate that stood above the packing clouds starts on the soil. A segmented wall's name places every segment. The distance moved is printed"),
                 }));
    t.push_back(box("packing.box"));
    t.push_back(size("packing.size"));
    t.push_back(sec("packing.exclude",
                 {
                     vec3("point", "`[x, y, z]`", "m", "**required**", "a point on the cylinder's axis", kCoord),
                     vec3("axis", "`[x, y, z]`", "–", "**required**", "the cylinder's axis (non-zero, normalised on reading)", kDirection),
                     num("radius", "number > 0", "m", "**required**", "its radius: no cloud grain is placed within this distance of the axis plus the grain's radius", R{1e-9, 1e3, '+', "m"}),
                 }));
    t.push_back(sec("packing.structures",
                 {
                     str("mesh", "mesh name", "", "**required**", "an `fem.meshes` name"),
                     integer("after_layer", "integer ≥ 0, < `layers`", "", "**required**", "its interface triangles (as a rigid facet wall) and its elements (as solid) join after this layer; grains overlapping them are removed then", R{1, 1000, '0', ""}),
                 }));
    t.push_back(sec("packing.surcharge",
                 {
                     str("material", "material name", "", "**required**", "the surcharge grains' material (its density sets the pressure)"),
                     num("thickness", "number > 0", "m", "**required**", "the layer's nominal thickness at the packing's porosity; at least one largest diameter", R{1e-6, 100, '+', "m"}),
                 }));
    t.push_back(sec("packing.shaking",
                 {
                     strings("walls", "list of wall names", "**required**", "e.g. `[xmin, xmax]`"),
                     num("amplitude", "number > 0", "m", "**required**", "a", R{1e-9, 10, '+', "m"}),
                     num("frequency", "number > 0", "Hz", "**required**", "f", R{1e-6, 1e6, '+', "Hz"}),
                     num("cycles", "number > 0", "", "`3`", "periods per layer", R{1e-6, 1e6, '+', ""}),
                     vec3("direction", "`[x, y, z]`", "", "`[1, 0, 0]`", "normalised", kDirection),
                 }));
    t.push_back(sec("packing.settle",
                 {
                     num("unbalanced", "number > 0", "–", "`0.01`", "a layer is in equilibrium when the unbalanced-force ratio (history.csv's) is below this …", R{1e-12, 1e3, '+', ""}),
                     num("kinetic", "number ≥ 0", "J", "`0` (unused)", "… and the kinetic energy per particle below this (applies to both criteria)", R{1e-30, 1e6, '0', "J"}),
                     integer("min_steps", "integer ≥ 0", "steps", "`0`", "per layer, shaking included: the fewest steps of a layer", kSettleSteps),
                     integer("max_steps", "integer > 0", "steps", "`200000`", "per layer, shaking included; at `max_steps` the next layer starts anyway (reported as not converged). `packing.json` says per layer which test ended it (`ended_by`: `unbalanced`, `porosity` or `max_steps`), with `criterion`, `bulk_porosity`, `porosity_change`, `window`, `kinetic_ratio` and `unbalanced` at the end", kSettleSteps),
                     integer("check_every", "integer > 0", "steps", "`200`", "steps between equilibrium checks", kSettleSteps),
                     word("criterion", "`auto`, `unbalanced` or `porosity`", {"auto", "unbalanced", "porosity"}, "`auto`", "what ends a layer. `unbalanced`: the unbalanced-force ratio (history.csv's) below `settle.unbalanced` (and `settle.kinetic`). `porosity`: the specimen's bulk porosity has stopped changing and no grain is still falling (below), or the `unbalanced` test, whichever comes first. `auto`: `porosity` when `friction` is 0, else `unbalanced`. A frictionless deposit creeps for 10⁵ steps with a ratio of 0.05–0.5 (higher the thinner the deposit) while its porosity no longer changes noticeably, so the ratio is no criterion there ([verification](verification.md#specimens-designmd-45))"),
                     num("porosity_change", "number > 0", "–", "`0.001`", "`porosity`: the bulk porosity n_b = 1 − V_s/(A·2 z̄_s) (V_s the grains' volume, A the box's section, z̄_s the height of the solid's centroid above the box's bottom; exact for a uniform column, biased by the loose top, used for its change) changed by less than this over the last `settle.window` steps …", R{1e-12, 1, '+', ""}),
                     integer("window", "integer > 0", "steps", "2√(d̄/g)/Δt", "… (default: the time a grain takes to fall two mean diameters from rest, rounded up to whole checks, at least 5 checks) …", kSettleSteps),
                     num("kinetic_ratio", "number > 0", "–", "`0.001`", "… and the kinetic energy per grain is below this times m̄·g·d̄ (mean grain mass and diameter): nothing is still falling. Applies to **both** criteria: a layer poured onto a specimen at rest would otherwise meet the ratio while still in the air (its grains' m g is small against the many resting contacts)", R{1e-12, 1e6, '+', ""}),
                 }));
    t.push_back(sec("packing.expansion",
                 {
                     integer("stages", "integer 1…100000", "", "`40`", "the number of equal growth factors from cloud_fraction to full size", R{1, 1e5, '+', ""}),
                     integer("stage_steps", "integer > 0", "steps", "`200`", "steps of relaxation per stage", R{1, 1e12, '+', "steps"}),
                 }));
    t.push_back(sec("packing.report",
                 {
                     num("margin", "number > 0", "m", "2 d_max", "inset of the report's interior box from the box's sides and bottom", kReport),
                     num("top_margin", "number > 0", "m", "3 d_max", "distance of the report's interior box below the specimen's surface (the highest grain top)", kReport),
                 }));
    // ---------------------------------------------------------------- holds
    t.push_back(sec("holds",
                 {
                     list("walls", "list", "", "**required**, non-empty", "the held walls: `{wall, stress}` each, see below", "holds.walls"),
                     num("tolerance", "number > 0", "–", "`0.01`", "a hold has converged when the unbalanced-force ratio and every held wall's misfit \\|σ − σ_target\\| / σ_target are below it", R{1e-12, 1e3, '+', ""}),
                     integer("check_every", "positive integer", "steps", "`1000`", "steps between the convergence checks, counted from the hold's start", R{1, 1e12, '+', "steps"}),
                     integer("min_steps", "integer ≥ 0", "steps", "`0`", "a hold runs at least this many steps", R{1, 1e12, '0', "steps"}),
                     integer("max_steps", "positive integer", "steps", "`1000000`", "a hold that has not converged ends after this many steps (reported; `holds.csv` says `converged 0`)", R{1, 1e12, '+', "steps"}),
                     num("creep", "number ≥ 0", "m", "`0`", "a hold has converged only when, besides, every held wall has moved less than this along its axis since the previous check (`check_every` steps earlier; a hold's first check counts from its start): a footing still sinking under its load -- a quasi-static flow, whose unbalanced forces are small -- does not count as converged; `0`: not checked", R{1e-12, 1, '0', "m"}),
                     map("stop", "`{wall, displacement}`", "", "none", "end the run once a servo wall has moved `displacement` (m) along its axis from its start (failure: e.g. a footing's settlement of 0.5 B)", "holds.stop"),
                 }));
    t.push_back(sec("holds.walls",
                 {
                     str("wall", "wall name", "", "**required**", "a servo wall (`motion: {servo: …}`, no schedule), or a segmented one (every segment); with `displacement`: a fixed wall (no `motion`, no schedule)"),
                     numbers("stress", "list of numbers > 0", "Pa", "one of `stress`, `displacement`", "the servo's target σ in each hold (replaces `servo.stress`); every held wall lists as many as there are holds", R{1e-6, 1e12, '+', "Pa"}),
                     numbers("displacement", "list of numbers", "m", "one of `stress`, `displacement`", "instead of a stress: the wall's displacement along `axis` from where the run started, in each hold (a retaining wall or a shaft moved in steps: thesis ch. 3); it moves there at `velocity`, and the hold converges only after it has arrived", R{1e-12, 1e3, '~', "m"}),
                     vec3("axis", "`[x, y, z]`", "–", "**required** with `displacement`", "the direction of the displacement (non-zero, normalised on reading)", kDirection),
                     num("velocity", "number > 0", "m/s", "**required** with `displacement`", "the speed at which the wall moves to each hold's displacement", R{1e-12, 1e4, '+', "m/s"}),
                 }));
    t.push_back(sec("holds.stop",
                 {
                     str("wall", "wall name", "", "**required**", "a servo wall"),
                     num("displacement", "number > 0", "m", "**required**", "along the wall's servo axis, from where the run started", R{1e-12, 1e3, '+', "m"}),
                 }));
    return t;
  }();
  return table;
}

}  // namespace fdem::schema
