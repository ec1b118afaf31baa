#include "cli.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>

#include "qsmesh/core/error.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/io/writer.hpp"
#include "qsmesh/parallel/pipeline.hpp"

namespace qsmesh::cli {

namespace {

double parse_positive(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    throw InputError(option + ": '" + text + "' is not a number");
  }
  if (used != text.size()) throw InputError(option + ": '" + text + "' is not a number");
  if (!std::isfinite(v) || v <= 0)
    throw InputError(option + ": must be positive, got '" + text + "'");
  return v;
}

std::string item_text(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// The whole of `text` as a number (strtod's syntax: inf and nan included), or nothing.
std::optional<double> parse_double(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0') return std::nullopt;
  return v;
}

/// The whole number `text` spells when it lies in [lo, hi]; nullopt otherwise (the caller says
/// which numbers the option takes).
std::optional<double> parse_whole(const std::string& text, double lo, double hi) {
  const auto n = parse_double(text);
  if (!n || !std::isfinite(*n) || *n < lo || *n > hi || *n != std::floor(*n)) return std::nullopt;
  return n;
}

// An option's iteration count: 0 (off) or 1..1000; anything else is refused naming the option.
int iterations_or_off(const std::string& opt, const std::string& v) {
  const auto n = parse_whole(v, 0, 1000);
  if (!n)
    throw InputError(opt + ": '" + v + "' is not 0 (off) or a number of iterations in [1, 1000]");
  return static_cast<int>(*n);
}

// An option that takes on or off.
bool on_or_off(const std::string& opt, const std::string& v) {
  if (v != "on" && v != "off") throw InputError(opt + ": '" + v + "' is not on or off");
  return v == "on";
}

int parse_threads(const std::string& text) {
  std::size_t used = 0;
  int v = 0;
  try {
    v = std::stoi(text, &used);
  } catch (const std::exception&) {
    throw InputError("--threads: '" + text + "' is not an integer");
  }
  if (used != text.size()) throw InputError("--threads: '" + text + "' is not an integer");
  if (v < 1) throw InputError("--threads: must be at least 1, got '" + text + "'");
  return v;
}

// A value each ID:VALUE option accepts, for its error messages.
const char* id_value_example(const std::string& option) {
  if (option == "--curve-edges") return "12:8,40:16";
  if (option == "--face-quads") return "3:500,7:1200";
  return "12:0.5,40:2";
}

/// "ID:VALUE[,ID:VALUE...]" with ids >= 0 and values > 0.
std::vector<std::pair<int, double>> parse_id_values(const std::string& option,
                                                    const std::string& text) {
  std::vector<std::pair<int, double>> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos)
      throw InputError(option + ": '" + item + "' is not ID:VALUE (e.g. " + option + " " +
                       id_value_example(option) + ")");
    const std::string id_text = item.substr(0, colon);
    std::size_t used = 0;
    int id = -1;
    try {
      id = std::stoi(id_text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != id_text.size() || id < 0)
      throw InputError(option + ": '" + id_text + "' is not an entity id (a non-negative integer)");
    out.emplace_back(id, parse_positive(option, item.substr(colon + 1)));
    start = end + 1;
  }
  return out;
}

/// Throws InputError when an id appears twice in one ID:VALUE option (over all its occurrences):
/// which of the two values the user meant cannot be guessed.
template <class T>
void check_unique_ids(const char* option, const char* what,
                      const std::vector<std::pair<int, T>>& items) {
  std::vector<int> ids;
  ids.reserve(items.size());
  for (const auto& item : items) ids.push_back(item.first);
  std::sort(ids.begin(), ids.end());
  const auto twice = std::adjacent_find(ids.begin(), ids.end());
  if (twice != ids.end())
    throw InputError(std::string(option) + ": " + what + " " + std::to_string(*twice) +
                     " is given twice; give each " + what + " once");
}

template <class T>
void append(std::vector<T>& to, const std::vector<T>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

std::string example_list() {
  std::string list;
  for (const auto& name : cad::example_names()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

}  // namespace

std::optional<cad::ExampleFormat> example_format(const std::string& path) {
  const std::string ext = io::lowercase_extension(path);
  if (ext == ".step" || ext == ".stp") return cad::ExampleFormat::Step;
  if (ext == ".brep" || ext == ".brp") return cad::ExampleFormat::Brep;
  return std::nullopt;
}

Arguments parse(const std::vector<std::string>& args) {
  Arguments a;
  if (args.empty()) return a;
  const std::string& cmd = args[0];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    a.command = Command::Help;
    if (args.size() > 1) a.help_topic = args[1];
    return a;
  }
  if (cmd == "--version") {
    a.command = Command::Version;
    return a;
  }
  if (cmd == "info")
    a.command = Command::Info;
  else if (cmd == "mesh")
    a.command = Command::Mesh;
  else if (cmd == "crossfield")
    a.command = Command::CrossField;
  else if (cmd == "sizemap")
    a.command = Command::SizeMap;
  else if (cmd == "example")
    a.command = Command::Example;
  else
    throw InputError("unknown command '" + cmd +
                     "' (commands: info, mesh, crossfield, sizemap, example; see qsmesh --help)");
  const bool meshing = a.command == Command::Mesh || a.command == Command::CrossField ||
                       a.command == Command::SizeMap;
  // Size-map options: the sizemap command and the mesh command (whose quad stages use the size
  // map; with --until background they are refused, see below).
  const bool sizing = a.command == Command::SizeMap || a.command == Command::Mesh;
  bool sizing_rules_given = false;  // --sizing on the line

  std::vector<std::string> positional;
  bool layout_given = false;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& opt = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw InputError(opt + ": missing value");
      return args[++i];
    };
    if (opt == "--help" || opt == "-h") {
      // Help alone, not the options parsed before it: those were never checked together.
      Arguments help_only;
      help_only.help_topic = cmd;
      help_only.command = Command::Help;
      return help_only;
    }
    if (opt == "-o" || opt == "--output")
      a.output = value();
    else if (opt == "--size" && (meshing || a.command == Command::Info))
      a.size = parse_positive(opt, value());
    else if (opt == "--size-factor" && (meshing || a.command == Command::Info))
      a.size_factor = parse_positive(opt, value());
    else if (opt == "--until" && a.command == Command::Mesh)
      a.until = value();
    else if (opt == "--method" && a.command == Command::Mesh) {
      a.method = value();
      // separatrix: paper 003's partition (fieldmesh); the others: paper 004's dispatch.
      a.separatrix_method = a.method == "separatrix";
      if (!a.separatrix_method && a.method != "default" && a.method != "holomorphic" &&
          a.method != "auto")
        throw InputError("--method: expected default, holomorphic, auto or separatrix, got '" +
                         a.method + "'");
    } else if (opt == "--smooth-groups" && a.command == Command::Mesh)
      a.smooth_groups = true;
    else if (opt == "--threads")
      a.threads = parse_threads(value());
    else if (opt == "--face-time-budget" && a.command == Command::Mesh)
      a.face_time_budget = parse_positive(opt, value());
    else if (opt == "--stats" && meshing)
      a.stats = value();
    else if (opt == "--field-divisions" && meshing) {
      const std::string& v = value();
      const auto n = parse_double(v);
      if (!n || !std::isfinite(*n) || *n < 0 || (*n > 0 && *n < 1) || *n > 1e6)
        throw InputError(opt + ": '" + v +
                         "' is not 0 (the background follows the target size) or a number of "
                         "divisions in [1, 1e6]");
      a.field_divisions = *n;
    } else if (opt == "--distributed-threshold" && meshing) {
      const std::string& v = value();
      const auto n = parse_whole(v, 1, 2e9);
      if (!n) throw InputError(opt + ": '" + v + "' is not a number of unknowns in [1, 2e9]");
      a.distributed_threshold = static_cast<LO>(*n);
    } else if (opt == "--field-change" && meshing) {
      const std::string& v = value();
      if (v != "max" && v != "rms") throw InputError(opt + ": '" + v + "' is not max or rms");
      a.field_change = v;
    } else if (opt == "--field-iterations" && meshing) {
      const std::string& v = value();
      const auto n = parse_whole(v, 1, 1000);
      if (!n) throw InputError(opt + ": '" + v + "' is not a number of iterations in [1, 1000]");
      a.field_iterations = static_cast<int>(*n);
    } else if (opt == "--field-shortcuts" && meshing) {
      const std::string& v = value();
      if (v != "all" && v != "uniform" && v != "none")
        throw InputError(opt + ": '" + v + "' is not all, uniform or none");
      a.field_shortcuts = v;
    } else if (opt == "--field-stall" && meshing) {
      // K or K:R.
      const std::string& v = value();
      const auto colon = v.find(':');
      const auto n = parse_whole(v.substr(0, colon), 0, 1000);
      if (!n)
        throw InputError(opt + ": '" + v +
                         "' does not start with 0 (off) or a number of iterations in [1, 1000]");
      a.field_stall = static_cast<int>(*n);
      if (colon != std::string::npos) {
        const auto r = parse_double(v.substr(colon + 1));
        if (!r || !std::isfinite(*r) || *r <= 0 || *r >= 1)
          throw InputError(opt + ": '" + v + "': the ratio after ':' is not in (0, 1)");
        a.field_stall_ratio = *r;
      }
    } else if (opt == "--field-stall-revolution" && meshing) {
      a.field_stall_revolution = iterations_or_off(opt, value());
    } else if (opt == "--field-settled" && meshing) {
      a.field_settled = iterations_or_off(opt, value());
    } else if (opt == "--field-regular" && meshing) {
      a.field_regular = on_or_off(opt, value());
    } else if (opt == "--block-structured" && a.command == Command::Mesh)
      a.block_structured = true;
    else if (opt == "--block-patches" && a.command == Command::Mesh)
      a.block_patches = true;
    else if (opt == "--plot3d-stream" && a.command == Command::Mesh)
      a.plot3d_stream = true;
    else if (opt == "--plot3d-single" && a.command == Command::Mesh)
      a.plot3d_single = true;
    // Paper 003 (fieldmesh): meshing from a given cross field.
    else if (opt == "--cross-field" && a.command == Command::Mesh)
      a.cross_field = value();
    else if (opt == "--layout" && a.command == Command::Mesh) {
      const std::string& v = value();
      if (v != "coarse" && v != "dense")
        throw InputError("--layout: '" + v + "' is not coarse or dense");
      a.coarse_layout = v == "coarse";
      layout_given = true;
    } else if (opt == "--loop-balance" && a.command == Command::Mesh) {
      const std::string& v = value();
      const auto b = parse_double(v);
      if (!b || !(*b >= 0 && *b <= 1))
        throw InputError("--loop-balance: '" + v + "' is not a number in [0, 1]");
      a.loop_balance = *b;
    } else if (opt == "--loop-widths" && a.command == Command::Mesh) {
      const std::string& v = value();
      if (v != "mean" && v != "fit")
        throw InputError("--loop-widths: '" + v + "' is not mean or fit");
      a.fit_loop_widths = v == "fit";
    } else if (opt == "--repairs" && a.command == Command::Mesh) {
      const std::string& v = value();
      if (v != "grow" && v != "local" && v != "restore")
        throw InputError("--repairs: '" + v + "' is not grow, local or restore");
      a.repairs = v == "grow"    ? layout::Repairs::Grow
                  : v == "local" ? layout::Repairs::Local
                                 : layout::Repairs::Restore;
    } else if (opt == "--fine-placement" && a.command == Command::Mesh) {
      const std::string& v = value();
      if (v != "former" && v != "laplacian" && v != "spacing" && v != "both" && v != "patch")
        throw InputError("--fine-placement: '" + v +
                         "' is not former, laplacian, spacing, both or patch");
      a.fine_laplacian = v == "laplacian" || v == "both" || v == "patch";
      a.fine_input_spacing = v == "spacing" || v == "both" || v == "patch";
      a.fine_patch = v == "patch";
    } else if (opt == "--cone-angle" && a.command == Command::Mesh) {
      const std::string& v = value();
      const auto d = parse_double(v);
      if (!d || !(*d > 0 && *d < 90))
        throw InputError("--cone-angle: '" + v + "' is not a number of degrees in (0, 90)");
      a.cone_angle_deg = *d;
    } else if (opt == "--curves-are-walls" && a.command == Command::Mesh) {
      a.sharp_and_smooth_walls = true;
    } else if (opt == "--traces-cross-curves" && a.command == Command::Mesh) {
      a.traces_cross_curves = true;
    } else if (opt == "--order" && a.command == Command::Mesh) {
      const std::string& v = value();
      if (v.size() != 1 || v[0] < '1' || v[0] > '5')
        throw InputError("--order: '" + v + "' is not 1, 2, 3, 4 or 5");
      a.order = v[0] - '0';
    } else if (opt == "--check" && a.command == Command::CrossField)
      a.check = true;
    else if (opt == "--curvature-edges" && sizing) {
      const std::string& v = value();
      const auto n = parse_double(v);
      if (!n || !std::isfinite(*n) || *n < 0 || (*n > 0 && *n < 3))
        throw InputError(
            opt + ": '" + v +
            "' is not 0 (no curvature sizes) or a number of edges per turn of at least 3");
      a.curvature_edges = *n;
    } else if (opt == "--face-curvature" && sizing) {
      a.face_curvature = true;
    } else if (opt == "--odd-slivers" && sizing) {
      a.odd_slivers = true;
    } else if (opt == "--one-edge-slivers" && sizing) {
      a.one_edge_slivers = true;
    } else if (opt == "--feature-ratio" && sizing) {
      const std::string& v = value();
      const auto r = parse_double(v);
      if (!r || !(*r >= 0 && *r <= 1))
        throw InputError(opt + ": '" + v + "' is not a number in [0, 1]");
      a.feature_ratio = *r;
    } else if (opt == "--thin-aspect" && sizing) {
      const std::string& v = value();
      const auto k = parse_double(v);
      if (!k || !std::isfinite(*k) || *k < 0)
        throw InputError(opt + ": '" + v + "' is not 0 (off) or a positive aspect ratio");
      a.thin_aspect = *k;
    } else if (opt == "--size-min" && sizing) {
      a.size_min = parse_positive(opt, value());
    } else if (opt == "--size-min-ratio" && sizing) {
      const std::string& v = value();
      const auto r = parse_double(v);
      if (!r || !(*r > 0 && *r <= 1))
        throw InputError(opt + ": '" + v + "' is not a number in (0, 1]");
      a.size_min_ratio = *r;
    } else if (opt == "--sizing" && sizing) {
      a.sizing = value();
      if (a.sizing == "gmsh") a.sizing = "clamped";  // the name it had before it was the default
      if (a.sizing != "clamped" && a.sizing != "paper")
        throw InputError("--sizing: unknown rules '" + a.sizing + "' (clamped, gmsh or paper)");
      sizing_rules_given = true;
    } else if (opt == "--sizemap" && sizing) {
      a.sizemap = value();
      if (a.sizemap != "features" && a.sizemap != "crossfield")
        throw InputError("--sizemap: unknown method '" + a.sizemap + "' (features or crossfield)");
    } else if (opt == "--quads" && sizing)
      a.quads = parse_positive(opt, value());
    else if (opt == "--curve-edges" && sizing) {
      for (const auto& [id, v] : parse_id_values(opt, value())) {
        if (v != std::floor(v))
          throw InputError(opt + ": curve " + std::to_string(id) +
                           ": edge count must be an integer");
        if (v > std::numeric_limits<int>::max())
          throw InputError(opt + ": curve " + std::to_string(id) + ": " + item_text(v) +
                           " edges is more than any mesh can hold");
        a.curve_edges.emplace_back(id, static_cast<int>(v));
      }
    } else if (opt == "--face-quads" && sizing)
      append(a.face_quads, parse_id_values(opt, value()));
    else if (opt == "--corner-size" && sizing)
      append(a.corner_sizes, parse_id_values(opt, value()));
    else if (opt == "--curve-size" && sizing)
      append(a.curve_sizes, parse_id_values(opt, value()));
    else if (opt == "--face-size" && sizing)
      append(a.face_sizes, parse_id_values(opt, value()));
    else if (opt == "--task-quads" && a.command == Command::Mesh) {
      const std::string& v = value();
      const auto n = parse_whole(v, 0, 1e15);
      if (!n) throw InputError(opt + ": '" + v + "' is not a whole number of quads (0: never cut)");
      a.task_quads = static_cast<std::int64_t>(*n);
    } else if (opt == "--pass-after-cuts" && a.command == Command::Mesh) {
      a.pass_after_cuts = on_or_off(opt, value());
    } else if (opt == "--second-pass-task" && a.command == Command::Mesh) {
      const std::string& v = value();
      const auto n = parse_whole(v, 0, 1e15);
      if (!n)
        throw InputError(opt + ": '" + v +
                         "' is not a whole number of irregular vertices (0: never)");
      a.second_pass_task = static_cast<std::int64_t>(*n);
    } else if (opt == "--fill-comparison" && a.command == Command::Mesh) {
      const std::string& v = value();
      if (v != "irregular" && v != "all" && v != "mean")
        throw InputError(opt + ": '" + v + "' is not irregular, all or mean");
      a.fill_comparison = v;
    } else if (opt == "--second-pass-quads" && a.command == Command::Mesh) {
      const std::string& v = value();
      const auto n = parse_whole(v, 0, 1e15);
      if (!n)
        throw InputError(opt + ": '" + v + "' is not a whole number of quads (0: no second pass)");
      a.second_pass_quads = static_cast<std::int64_t>(*n);
    } else if (opt == "--max-quads" && meshing) {
      const std::string& v = value();
      const auto n = parse_double(v);
      if (!n || !std::isfinite(*n) || *n < 0)
        throw InputError(opt + ": '" + v + "' is not a number of quads (0: no bound)");
      a.max_quads = *n;
    } else if (opt == "--json" && a.command == Command::Info)
      a.json = true;
    else if (opt == "--partition" && a.command == Command::Info) {
      const std::string& v = value();
      std::size_t start = 0;
      while (start <= v.size()) {
        const std::size_t end = std::min(v.find(',', start), v.size());
        const std::string item = v.substr(start, end - start);
        std::size_t used = 0;
        int p = 0;
        try {
          p = std::stoi(item, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != item.size() || p < 1)
          throw InputError(opt + ": '" + item +
                           "' is not a number of ranks (e.g. --partition 2,4,64)");
        a.partition.push_back(p);
        start = end + 1;
      }
    } else if (opt == "--sew")
      a.sew = true;
    else if (opt == "--quiet" || opt == "-q")
      a.quiet = true;
    else if (opt == "--verbose" || opt == "-v")
      a.verbose = true;
    else if (!opt.empty() && opt[0] == '-' && opt.size() > 1)
      throw InputError("unknown option '" + opt + "' for '" + cmd + "' (see qsmesh " + cmd +
                       " --help)");
    else
      positional.push_back(opt);
  }
  check_unique_ids("--curve-edges", "curve", a.curve_edges);
  check_unique_ids("--curve-size", "curve", a.curve_sizes);
  check_unique_ids("--face-quads", "face", a.face_quads);
  check_unique_ids("--face-size", "face", a.face_sizes);
  check_unique_ids("--corner-size", "corner", a.corner_sizes);
  if (a.size && a.size_factor) throw InputError("--size and --size-factor: give one, not both");
  if (a.size_min && a.size_min_ratio)
    throw InputError("--size-min and --size-min-ratio: give one, not both");
  // The size-map options asked for on the line; the default rules' own options (below) are not.
  const bool sizing_given =
      sizing_rules_given || a.sizemap != "crossfield" || a.quads > 0 || a.curvature_edges ||
      a.face_curvature || a.feature_ratio || a.thin_aspect || a.size_min || a.size_min_ratio ||
      !a.curve_edges.empty() || !a.face_quads.empty() || !a.corner_sizes.empty() ||
      !a.curve_sizes.empty() || !a.face_sizes.empty() || a.odd_slivers || a.one_edge_slivers;
  if (a.command == Command::Mesh && sizing_given && a.until == "background")
    throw InputError(
        "size-map options act on the quad mesh: with --until background only --size or "
        "--size-factor applies");
  // The clamped rules as the two options that make them; options given explicitly win.
  if (sizing && a.sizing == "clamped") {
    if (!a.curvature_edges) a.curvature_edges = 0.0;
    if (!a.size_min && !a.size_min_ratio) a.size_min_ratio = kClampedSizeMinRatio;
  }

  if (a.command == Command::Example) {
    if (positional.size() != 1)
      throw InputError("example: give one example name (available: " + example_list() + ")");
    a.example_name = positional[0];
    const auto names = cad::example_names();
    if (std::find(names.begin(), names.end(), a.example_name) == names.end())
      throw InputError("example: unknown example '" + a.example_name +
                       "' (available: " + example_list() + ")");
    if (a.output.empty()) throw InputError("example: missing -o FILE.step");
    if (!example_format(a.output))
      throw InputError(
          "example: cannot write '" + a.output +
          "': the extension picks the CAD format, .step/.stp (STEP) or .brep/.brp (BREP)");
  } else {
    if (positional.empty()) throw InputError(cmd + ": missing MODEL file (STEP, IGES or BREP)");
    if (positional.size() > 1)
      throw InputError(cmd + ": unexpected argument '" + positional[1] + "'");
    a.model = positional[0];
    if (a.command == Command::Mesh && a.output.empty())
      throw InputError("mesh: missing -o OUT (.cgns, .vtu, .msh, .h5 or .xyz)");
    const bool plot3d =
        a.command == Command::Mesh && io::output_format(a.output) == io::Format::kPlot3d;
    if ((a.plot3d_stream || a.plot3d_single) && !plot3d)
      throw InputError(std::string(a.plot3d_stream ? "--plot3d-stream" : "--plot3d-single") +
                       ": only for PLOT3D output (-o FILE.xyz or FILE.p3d)");
    if (plot3d) {
      // PLOT3D holds structured blocks only: the layout is what it writes.
      if (a.until == "background")
        throw InputError("-o " + a.output +
                         ": PLOT3D holds the blocks of a quad mesh; not with --until background");
      if (a.order > 1)
        throw InputError("-o " + a.output + " with --order " + std::to_string(a.order) +
                         ": PLOT3D blocks of high-order quads are not written");
      a.block_structured = true;
    }
    if (a.smooth_groups && a.method != "holomorphic" && a.method != "auto")
      throw InputError("--smooth-groups: only with --method holomorphic or auto");
    if (a.smooth_groups && a.until == "background")
      throw InputError("--smooth-groups needs a quad mesh: not with --until background");
    if (a.smooth_groups && a.block_structured)
      throw InputError(
          "--smooth-groups: a group's quads cross its faces' curves, which the blocks of "
          "--block-structured follow; not together");
    if (a.block_patches) {
      if (a.order < 2)
        throw InputError(
            "--block-patches: give --order N (2..5), the order of the Lagrange quad of each block");
      if (plot3d || a.block_structured)
        throw InputError(
            "--block-patches writes each block as one high-order quad (-o FILE.vtu, .msh, .h5 or "
            ".cgns); not with --block-structured or PLOT3D, which write each block as a grid");
      if (a.until == "background")
        throw InputError("--block-patches needs a quad mesh: not with --until background");
      if (a.smooth_groups)
        throw InputError(
            "--smooth-groups: a group's quads cross its faces' curves, which the blocks of "
            "--block-patches follow; not together");
      // A patch per block is worth having when the blocks are few and large: the coarse layout.
      if (!layout_given) a.coarse_layout = true;
    }
    if (layout_given && !a.block_structured && !a.block_patches)
      throw InputError(
          "--layout: only with --block-structured or --block-patches (or -o FILE.xyz)");
    if (a.block_structured) {
      if (io::output_format(a.output) != io::Format::kCgns && !plot3d)
        throw InputError(
            "--block-structured: the blocks are written as CGNS or PLOT3D; give -o FILE.cgns or "
            "FILE.xyz");
      if (a.until == "background")
        throw InputError("--block-structured needs a quad mesh: not with --until background");
      if (a.order > 1)
        throw InputError("--block-structured with --order " + std::to_string(a.order) +
                         ": the blocks' grids are of linear quads; for one high-order quad per "
                         "block give --block-patches instead of --block-structured");
    }
    if (a.order > 1 && a.until == "background")
      throw InputError("--order " + std::to_string(a.order) +
                       " needs a quad mesh: not with --until background");
    if (a.order > 4 && io::output_format(a.output) == io::Format::kCgns)
      throw InputError("--order " + std::to_string(a.order) +
                       ": CGNS has no elements of order 5 (QUAD_25, order 4, is the highest); "
                       "write .vtu, .msh or .h5");
    if (a.method != "default" && a.until == "background")
      throw InputError("--method " + a.method + " needs a quad mesh: not with --until background");
    if (!a.cross_field.empty() && a.until == "background")
      throw InputError("--cross-field needs a quad mesh: not with --until background");
    if (a.command == Command::CrossField && a.output.empty() && !a.check)
      throw InputError("crossfield: missing -o OUT.vtu (or --check)");
    if (a.command == Command::SizeMap && a.output.empty())
      throw InputError("sizemap: missing -o OUT.vtu");
  }
  return a;
}

std::string help(const std::string& topic) {
  std::ostringstream os;
  if (topic == "info") {
    os << "usage: qsmesh info MODEL [--json] [--sew] [--partition P,... [--size H | --size-factor "
          "F]]\n\n"
          "Reads a CAD model (STEP .step/.stp, IGES .iges/.igs, BREP .brep/.brp) and prints its "
          "topology:\n"
          "the numbers of corners, curves and faces, the bounding box, and one line per face\n"
          "(surface type, loops, curve uses, seams, area).\n\n"
          "  --json           print the same as one JSON object (keys: corners, curves, faces, "
          "face_list, ...)\n"
          "  --sew            sew faces that arrive disconnected before building the topology\n"
          "  --partition P,...  also the METIS partition of the faces over P ranks that\n"
          "                   `mpirun -np P qsmesh mesh` uses at the same size (--size or "
          "--size-factor,\n"
          "                   default 0.02): per P, faces per rank, estimated cost and\n"
          "                   cross-field cost max / mean; with --json each face's rank (key\n"
          "                   partitions, by P)\n";
  } else if (topic == "mesh") {
    os << "usage: [mpirun -np P] qsmesh mesh MODEL -o OUT [options]\n\n"
          "Meshes every face of a CAD model and writes the surface mesh to OUT; the extension "
          "picks\n"
          "the format: .cgns (CGNS, unstructured zone, one section and family per CAD face and "
          "curve),\n"
          ".vtu (VTK XML, opens in ParaView; cell data cad_face), .msh (Gmsh 4.1 with entities),\n"
          ".h5 (HDF5 datasets for solvers: coordinates, quads, CAD ids and parameters of every\n"
          "vertex; an XDMF file of the same name, .xdmf, is written beside it to open in "
          "ParaView),\n"
          ".xyz or .p3d (multi-block PLOT3D of the quad layout's blocks, as --block-structured:\n"
          "whole, binary, double precision, little-endian, each block ni+1 x nj+1 x 1 points in\n"
          "Fortran unformatted records, as CFL3D and ParaView's PLOT3D reader read; beside it\n"
          "OUT.json lists each block's 1-to-1 interfaces and its free sides with their CGNS\n"
          "family names. Faces that do not split into blocks are left out, with a warning).\n"
          "Faces are distributed over the MPI ranks (METIS) and over threads inside a rank; the "
          "mesh\n"
          "is the same whatever the numbers of ranks and threads.\n\n"
          "  -o, --output OUT      output file (written under a temporary name, renamed at the "
          "end)\n"
          "  --size H              largest edge length, in model units (STEP: millimetres)\n"
          "  --size-factor F       largest edge length as a fraction of the model's bounding-box\n"
          "                        diagonal (default "
       << kDefaultSizeFactor
       << " when --size is not given)\n"
          "  --until STAGE         last pipeline stage to run: background (the curvature- and\n"
          "                        feature-adapted triangulation), unstructured (the all-quad "
          "mesh\n"
          "                        of paper 000 Sec. 5 on the quantized curves) or "
          "quasi-structured\n"
          "                        (the default: simple CAD faces meshed by patterns, Sec. 6.1, "
          "the\n"
          "                        others unstructured, then cavity and disk remeshing, Sec. "
          "6.2-6.3)\n"
          "  --threads T           threads per rank (default: the cores of the machine divided\n"
          "                        among the ranks running on it; more than the cores a rank may\n"
          "                        run on are not granted, and the run says so)\n"
          "  --stats FILE.json     also write the run statistics as JSON\n"
          "  --method M            per-face method of the quad stages: default; holomorphic "
          "(faces\n"
          "                        that are topological annuli, such as cylinders between two\n"
          "                        circles, meshed as a grid without singularity from their\n"
          "                        holomorphic 1-form, paper 004, when both loops have the same\n"
          "                        count: the quantization makes them equal where it can); auto\n"
          "                        (that grid only where it has fewer interior irregular\n"
          "                        vertices and SICN min and avg at most 0.02 below the default\n"
          "                        mesh's). Other faces keep the default mesh, the reason\n"
          "                        in the face_stats of --stats (\"holomorphic\"); separatrix\n"
          "                        (paper 003's partition into four-sided regions on the mesher's\n"
          "                        own cross field, filled by transfinite interpolation; a face\n"
          "                        where it fails keeps the default mesh, \"field_refusal\")\n"
          "  --smooth-groups       with --method holomorphic or auto: faces joined across smooth\n"
          "                        (G1) curves, such as a fillet between two pipes, meshed as one\n"
          "                        surface from its holomorphic 1-form; the quads cross the inner\n"
          "                        curves and each goes to the face holding its centre; the outer\n"
          "                        loops' counts come from the form (not with --block-structured)\n"
          "  --order N             high-order elements, N = 2..5: Lagrange quads of (N+1)^2 nodes\n"
          "                        and bars of N+1 nodes, the new nodes on the CAD; a quad that\n"
          "                        would fold gets its face nodes along the face's parameter\n"
          "                        lines, else straightened (CGNS QUAD_9/16/25 and BAR_3/4/5, so\n"
          "                        N <= 4 there; VTU Lagrange cells; MSH; in .h5 the datasets\n"
          "                        quadM and barN+1, and the .xdmf shows order 2 curved, higher\n"
          "                        orders as the linear quads of their corners)\n"
          "  --block-structured    write the .cgns file as structured zones, one per block,\n"
          "                        joined by 1-to-1 connectivity (see --layout)\n"
          "  --block-patches       with --order N: each block of the layout (coarse unless\n"
          "                        --layout dense) written as one Lagrange quad of order N on\n"
          "                        the CAD, a light model of the surface (paper 002 Sec. IV.F;\n"
          "                        .vtu, .msh, .h5 or .cgns)\n"
          "  --layout dense|coarse the blocks of --block-structured (and of .xyz). dense "
          "(default):\n"
          "                        the layout of the quad mesh as it is (traces from irregular\n"
          "                        vertices and CAD corners, paper 002 Sec. III.A; blocks may "
          "meet\n"
          "                        along part of a side); faces that do not split into blocks go\n"
          "                        to one unstructured zone. coarse: a new mesh on a conforming\n"
          "                        layout (paper 002 Sec. III-IV: T-mesh, ILP, subdivision,\n"
          "                        smoothing), every block side shared whole, every sharp CAD\n"
          "                        curve a block side; its quads are still worse than the mesh it "
          "comes\n"
          "                        from (docs/benchmarks.md); when it fails, one log line and\n"
          "                        the dense layout\n"
          "  --loop-balance B      with --layout coarse: quad-loop widths blended with weight B\n"
          "                        (0..1) towards square fine quads in each coarse quad\n"
          "                        (default 0: the input mesh's lengths alone)\n"
          "  --loop-widths W       with --layout coarse: mean (default: each quad loop's width\n"
          "                        the rounded mean of its input lengths) or fit (the width\n"
          "                        nearest in ratio to the input extent of every cell it crosses)\n"
          "  --repairs R           with --layout coarse, where fine quads fold: grow (default:\n"
          "                        their patches and rings around them are kept from\n"
          "                        collapsing, then grown one coarse unit at a time, before\n"
          "                        input lengths are restored), local (kept from collapsing,\n"
          "                        then input lengths) or restore (a patch's second repair\n"
          "                        restores its input lengths)\n"
          "  --fine-placement P    with --layout coarse: former, laplacian, spacing, both\n"
          "                        (default) or patch: the uv Laplacian before the kernels, fine\n"
          "                        nodes on CAD curves spaced like the input mesh's (both), and\n"
          "                        fine nodes inside faces placed from the input patch's grid\n"
          "  --cone-angle DEG      with --layout coarse: half-angle of the T-mesh traces' cone\n"
          "                        (stopping rule and geometric consistency; default 45, the\n"
          "                        paper's): larger gives fewer, more distorted blocks\n"
          "  --curves-are-walls    with --layout coarse: every CAD curve a block side; by\n"
          "                        default traces and blocks cross the curves where the surface\n"
          "                        is smooth (normals within 10 degrees), sharp ones only are\n"
          "                        walls\n"
          "  --traces-cross-curves with --layout coarse: the T-mesh's traces run on across\n"
          "                        smooth curves too (more blocks on A319: docs/benchmarks.md)\n"
          "  --plot3d-stream       PLOT3D output without the Fortran record lengths (C stream\n"
          "                        binary: the same bytes, nothing between the records)\n"
          "  --plot3d-single       PLOT3D coordinates in single precision (float32)\n"
          "  --cross-field FIELD   mesh the faces FIELD gives a cross field for from that field\n"
          "                        (paper 003: compatibility, alignment, separatrices, four-sided\n"
          "                        regions, transfinite filling); FIELD is a list of singular\n"
          "                        points per face or a `qsmesh crossfield` VTU (docs/usage.md).\n"
          "                        A face whose field is refused keeps the default mesh\n"
          "  --quads N, --curvature-edges N, --face-curvature, --feature-ratio R, --thin-aspect "
          "K,\n"
          "  --size-min H, --size-min-ratio R, --sizing RULES, --curve-edges C:N,.., "
          "--odd-slivers,\n"
          "  --one-edge-slivers,\n"
          "  --face-quads F:N,.., --corner-size K:H,.., --curve-size C:H,.., --face-size F:H,..,\n"
          "  --sizemap METHOD\n"
          "                        size-map controls, as for sizemap (see qsmesh sizemap --help);\n"
          "                        they act on the quad mesh, not with --until background\n"
          "  --field-divisions N   the background triangulation, on which the cross fields and "
          "the\n"
          "                        size map are computed, follows the geometry: curvature, small\n"
          "                        CAD features, and edges of at most the face's bounding-box\n"
          "                        diagonal / N (default "
       << kDefaultFieldDivisions
       << ") or the target size, whichever\n"
          "                        is larger; the quad stages sample the fields. 0: the "
          "background\n"
          "                        follows the target size (paper 000 Sec. 3.1; its cost grows\n"
          "                        faster than the mesh)\n"
          "  --distributed-threshold N\n"
          "                        a face whose field system has at least N unknowns is solved\n"
          "                        by all ranks together (MUMPS over the ranks; default "
       << linalg::SolverOptions{}.distributed_threshold
       << ");\n"
          "                        the mesh is the same at any rank count\n"
          "  --field-change M      how a cross-field diffusion level measures its convergence:\n"
          "                        max (default: the largest change of any edge's cross) or rms\n"
          "                        (the area-weighted root mean square; fewer solves, another\n"
          "                        mesh: docs/benchmarks.md, issue 27, branch field2)\n"
          "  --field-iterations N  at most N iterations per cross-field diffusion level (default "
       << crossfield::CrossFieldOptions{}.max_iterations_per_level
       << ")\n"
          "  --field-stall K[:R]   a cross-field diffusion level also ends when its RMS change\n"
          "                        has not fallen below R times its value K iterations earlier\n"
          "                        (a stalled level: singularities creeping a cell at a time);\n"
          "                        0: off (default "
       << crossfield::CrossFieldOptions{}.stall_window << "; R default "
       << crossfield::CrossFieldOptions{}.stall_ratio
       << ")\n"
          "  --field-stall-revolution K\n"
          "                        the same rule, with ratio R, on the faces of revolution\n"
          "                        that are solved (not taken by --field-shortcuts) while\n"
          "                        --field-stall is off: their singularities drift about the\n"
          "                        axis and the levels would run to the cap; 0: off (default "
       << crossfield::CrossFieldOptions{}.revolution_stall_window
       << ")\n"
          "  --field-settled K     a diffusion level that converges within K iterations, the\n"
          "                        field no longer moving as the diffusion shrinks, skips the\n"
          "                        levels left but the last; 0: every level is solved (default "
       << crossfield::CrossFieldOptions{}.settled_level_iterations
       << ")\n"
          "  --field-regular on|off\n"
          "                        a level settled in --field-settled iterations on a field\n"
          "                        without singularity ends the diffusion, the last level\n"
          "                        included; off: it skips to the last level (default "
       << (crossfield::CrossFieldOptions{}.settled_regular_ends ? "on" : "off")
       << ")\n"
          "  --field-shortcuts S   faces whose cross field is known in closed form take it\n"
          "                        without a solve: planar faces bounded by lines at right\n"
          "                        angles, and faces of revolution (cylinders, cones, tori,\n"
          "                        spheres) bounded by their parallels and meridians. all\n"
          "                        (default), uniform (the planar ones only) or none\n"
          "  --face-time-budget S  at most S seconds of cavity remeshing (paper 000 Sec. 6.2) per\n"
          "                        face; a face that reaches it keeps the mesh it has (valid) and "
          "is\n"
          "                        counted in the summary. Without it the work is bounded by\n"
          "                        iteration counts only and the mesh does not depend on timing\n"
          "  --task-quads N        improve a face of more than N quads (default "
       << parallel::kDefaultTaskQuads
       << ") in pieces, each\n"
          "                        a task of its own for the ranks and threads, in two passes\n"
          "                        whose cuts alternate; 0: never. The mesh depends on N, not on\n"
          "                        the rank or thread count\n"
          "  --pass-after-cuts on|off\n"
          "                        after its pieces, a face cut by --task-quads is improved once\n"
          "                        more whole, as a task of a third pass: the irregular vertices\n"
          "                        its cuts held back go (default on)\n"
          "  --second-pass-quads N faces of at most N quads (default "
       << parallel::PipelineOptions{}.second_pass_max_quads
       << ") left with irregular\n"
          "                        vertices their cross field does not ask for are improved a\n"
          "                        second time with looser cavity bounds, and keep that mesh\n"
          "                        when it has fewer irregular vertices at a small SICN cost\n"
          "                        (docs/architecture.md); 0: no second pass (faster)\n"
          "  --fill-comparison M   which pattern fills kept by their thresholds are compared\n"
          "                        with the face's unstructured mesh, which replaces them when\n"
          "                        better: irregular (the default: fills of at most "
       << parallel::PipelineOptions{}.patterns.compare_irregular_max_quads
       << " quads\n"
          "                        with more interior irregular vertices than the face's\n"
          "                        cross field has singularities too, replaced by a mesh with\n"
          "                        fewer at no worse SICN min and mean; slower), all (as\n"
          "                        irregular, but every fill with an interior irregular vertex;\n"
          "                        slower still) or mean (only fills of a poor mean, replaced\n"
          "                        by a clearly better mean; the default with --layout coarse,\n"
          "                        whose blocks follow the fills)\n"
          "  --second-pass-task N  a face with at least N irregular vertices (default "
       << parallel::kDefaultSecondPassTaskIrregular
       << ")\n"
          "                        before its improvement runs its second pass as a task of its\n"
          "                        own, beside the first; 0: never. The mesh is the same\n"
          "  --max-quads N         refuse, before any work, a run whose estimated quad count is\n"
          "                        above N (default "
       << kDefaultMaxQuads
       << "; 0: no bound). A run is\n"
          "                        also refused when the memory it would need, estimated from the\n"
          "                        same count, is more than this machine has\n"
          "  --sew                 sew faces that arrive disconnected\n"
          "  -q, --quiet           print only warnings and errors\n"
          "  -v, --verbose         print per-face details (with the quad stages: method, why no\n"
          "                        pattern was kept, counts, irregular vertices, SICN and time of\n"
          "                        every face)\n\n"
          "Exit codes: 0 success, 2 bad input (one line on stderr says what to fix), 1 the output\n"
          "could not be written (disk full, say; nothing half-written is left) or an internal "
          "error.\n";
  } else if (topic == "crossfield") {
    os << "usage: [mpirun -np P] qsmesh crossfield MODEL [-o OUT.vtu] [--check] [options]\n\n"
          "Computes, on the background triangulation of every CAD face, the boundary-aligned "
          "cross\n"
          "field (multilevel heat diffusion, paper 000 Sec. 3.1), its singularities (Sec. 3.2) "
          "and\n"
          "its conformal scaling H, h = exp(H) (Sec. 3.3). OUT.vtu holds the triangulation with "
          "cell\n"
          "data cross_u and cross_v (the two cross directions), u_norm (|U| before projection), H, "
          "h,\n"
          "and the singularities as vertex cells with cell data singularity_index (+1: valence 3,\n"
          "-1: valence 5). The summary lists, per face, its singularities and whether they "
          "satisfy\n"
          "the Euler relation of the face (paper 000 Eq. 2).\n\n"
          "  -o, --output OUT.vtu  output file (VTK XML, opens in ParaView)\n"
          "  --check               list the faces whose singularities break the Euler relation and "
          "end\n"
          "                        with the line 'euler-consistent: K/N'\n"
          "  --size H, --size-factor F, --threads T, --stats FILE.json, --max-quads N,\n"
          "  --field-divisions N, --distributed-threshold N, --field-change M,\n"
          "  --field-iterations N, --field-stall K[:R], --field-stall-revolution K,\n"
          "  --field-settled K, --field-regular on|off, --field-shortcuts S,\n"
          "  --sew, -q, -v:\n"
          "                        as for mesh\n";
  } else if (topic == "sizemap") {
    os << "usage: [mpirun -np P] qsmesh sizemap MODEL -o OUT.vtu [options]\n\n"
          "Computes the size map (paper 000 Sec. 4.1-4.2) and the curve quantization (Sec. 4.3):\n"
          "OUT.vtu holds the background triangulation with point data s (the size map), s_min "
          "(small\n"
          "CAD features) and s_cf (cross-field conformal sizes), the background curve meshes, and "
          "the\n"
          "vertices of the quantized curve meshes as vertex cells. The summary gives the numbers "
          "of\n"
          "curves, chords and edges.\n\n"
          "  --sizemap METHOD      features (small features and user sizes only) or crossfield\n"
          "                        (also the conformal scaling of the cross fields; default)\n"
          "  --quads N             target number of quads of the model (default: area / size^2)\n"
          "  --curvature-edges N   edges per full turn on curved curves: a radius R gets edges of\n"
          "                        2 pi R / N at most (default 0 with the default sizing rules,\n"
          "                        16 with --sizing paper); 0 sizes by the cross field and the\n"
          "                        small CAD features only (paper 000 Sec. 4)\n"
          "  --face-curvature      the same bound from the faces' curvature along their curves\n"
          "                        (finer on curved faces, e.g. a wing's leading edge, but the\n"
          "                        isotropic sizes then make the counts of opposite sides "
          "unequal)\n"
          "  --feature-ratio R     small CAD features (curves closer than the size) refine the\n"
          "                        size to no less than R times what it is without them (default\n"
          "                        0.75); 0 resolves every feature, at the price of more "
          "irregular\n"
          "                        vertices along thin strips and slots\n"
          "  --thin-aspect K       along a face narrower than half the size (a strip, a neck),\n"
          "                        edges are at most K times its width long, so that its quads\n"
          "                        keep SICN about 1 / K (default 4; 0: off)\n"
          "  --size-min H          smallest size the size map may ask for (model units; default\n"
          "                        0.17 x the size cap with the default sizing rules, the size\n"
          "                        cap / 100 with --sizing paper); given, it also stops curves\n"
          "                        shorter than H (sliver edges of the CAD) from refining the "
          "mesh\n"
          "                        around them (they keep their 2 edges)\n"
          "  --size-min-ratio R    the same floor as R times the size cap. With\n"
          "                        --curvature-edges 0 it sizes about as Gmsh's implementation of\n"
          "                        the paper does (no curvature sizes, no feature finer than a\n"
          "                        fraction of the target size): fewer irregular vertices and\n"
          "                        flatter quads against sliver curves; at coarse sizes curved\n"
          "                        faces may get too few edges and fail (docs/benchmarks.md)\n"
          "  --sizing RULES        clamped (the default; gmsh is another name for it, the rules\n"
          "                        of Gmsh's implementation): --curvature-edges 0\n"
          "                        --size-min-ratio 0.17, options given explicitly still win; no\n"
          "                        size below the floor, so quads against a sliver curve are\n"
          "                        flat. paper: paper 000 Sec. 4.1, a sliver curve refines the\n"
          "                        mesh around it down to its length, with curvature sizes of\n"
          "                        16 edges per turn and the floor the size cap / 100\n"
          "  --curve-edges C:N,..  prescribe the number of edges of curves, kept exactly (odd\n"
          "                        too: each face loop must stay even; refused when none can)\n"
          "  --odd-slivers         a curve nearer 1 edge than 2 (its size map's count below\n"
          "                        sqrt 2) takes 1 edge, the loops kept even by other curves;\n"
          "                        off by default (measured: docs/benchmarks.md)\n"
          "  --one-edge-slivers    a curve shorter than a tenth of the size floor takes 1 edge,\n"
          "                        its corners at most 10 x its length even beside four-sided\n"
          "                        faces; off by default (measured: docs/benchmarks.md)\n"
          "  --face-quads F:N,..   prescribe the number of quads of faces\n"
          "  --corner-size K:H,.., --curve-size C:H,.., --face-size F:H,..\n"
          "                        size constraints at corners, on curves, on faces (model units)\n"
          "  --size H, --size-factor F, --threads T, --stats FILE.json, --max-quads N,\n"
          "  --field-divisions N, --distributed-threshold N, --field-change M,\n"
          "  --field-iterations N, --field-stall K[:R], --field-stall-revolution K,\n"
          "  --field-settled K, --field-regular on|off, --field-shortcuts S,\n"
          "  --sew, -q, -v:\n"
          "                        as for mesh\n";
  } else if (topic == "example") {
    os << "usage: qsmesh example NAME -o FILE\n\n"
          "Writes a built-in CAD model built with OpenCASCADE, as STEP (FILE.step, .stp) or BREP\n"
          "(FILE.brep, .brp). Millimetres.\n"
          "  wing-body         a fuselage of revolution fused with a wing lofted from NACA\n"
          "                    4-digit sections (10 m long)\n"
          "  far-field         the wing-body cut out of a 50 x 50 x 30 m box: an external flow\n"
          "                    domain with six huge planar faces\n"
          "  perforated-plate  a 2000 x 1000 x 20 plate with 72 holes of radius 30, 45 and 60:\n"
          "                    two faces with 73 loops each\n";
  } else {
    os << "qsmesh - quasi-structured quadrilateral surface meshes of CAD models, distributed with "
          "MPI\n\n"
          "usage: qsmesh COMMAND [options]\n\n"
          "commands:\n"
          "  info MODEL            print the CAD topology (corners, curves, faces)\n"
          "  mesh MODEL -o OUT     mesh the model and write OUT (.cgns, .vtu, .msh, .h5, .xyz)\n"
          "  crossfield MODEL -o OUT.vtu\n"
          "                        cross fields, singularities and scaling of every face\n"
          "  sizemap MODEL -o OUT.vtu\n"
          "                        size map and curve quantization\n"
          "  example NAME -o FILE  write a built-in CAD model (wing-body, far-field,\n"
          "                        perforated-plate) as STEP or BREP\n\n"
          "Run 'qsmesh COMMAND --help' for the options of a command.\n"
          "Quick start:\n"
          "  qsmesh example wing-body -o wing_body.step\n"
          "  mpirun -np 2 qsmesh mesh wing_body.step -o wing_body.cgns --stats stats.json\n";
  }
  return os.str();
}

}  // namespace qsmesh::cli
