// Transmittance laws and source/scatterer pairs (weft/transmittance), vectorized over numpy.
#include <cmath>
#include <span>
#include <string>

#include "common.h"
#include "weft/core/memory.h"
#include "weft/core/rng.h"
#include "weft/transmittance/draws.h"
#include "weft/transmittance/pair.h"
#include "weft/transmittance/registry.h"

namespace weft::python {
namespace {

namespace tr = weft::transmittance;

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// f(t) elementwise over an array of distances t >= 0 (NaN and negative refused), same shape;
/// a 0-d input (a Python number) gives a Python float.
template <typename F>
py::object elementwise(const char* what, const Array& t, F&& f) {
  const py::ssize_t n = t.size();
  const double* in = t.data();
  for (py::ssize_t q = 0; q < n; ++q) {
    if (std::isnan(in[q]) || in[q] < 0.0) fail("{}: distances t must be >= 0, got {} at index {}", what, in[q], q);
  }
  if (t.ndim() == 0) return py::float_(f(in[0]));
  Array out(std::vector<py::ssize_t>(t.shape(), t.shape() + t.ndim()));
  double* o = out.mutable_data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t q = 0; q < n; ++q) o[q] = f(in[q]);
  }
  return out;
}

py::dict parameters(const tr::Law& law) {
  py::dict d;
  for (const auto& p : law.parameters()) d[py::str(p.name)] = p.value;
  return d;
}

std::uint64_t sample_count(long long n) {
  if (n < 0) fail("sample: n must be >= 0, got {}", n);
  if (static_cast<std::uint64_t>(n) > tr::kMaxDraws)
    fail("sample: at most 1e9 samples per call, got {} (use several seeds)", n);
  // The array holds every draw at once: the budget rule of every "estimate before spending"
  // guard (weft/core/memory.h), checked before allocating.
  const std::uint64_t bytes = static_cast<std::uint64_t>(n) * sizeof(double);
  if (bytes > default_memory_budget())
    fail("sample: {} samples would take {}, over the memory budget of {}: draw fewer per call (several seeds)", n,
         format_bytes(bytes), format_bytes(default_memory_budget()));
  return static_cast<std::uint64_t>(n);
}

/// n draws from one stream stream_for(seed, 0), as `weft model --sample N --seed S` prints them,
/// chunk by chunk with progress reports: Ctrl-C or a raising callback stops it at the next chunk.
py::array_t<double> draw(const tr::TransmittancePair& pair, tr::Origin from, long long n, std::uint64_t seed,
                         const py::object& progress) {
  const std::uint64_t count = sample_count(n);
  std::vector<double> values = run_released(progress, [&](ProgressSink& sink) {
    std::vector<double> drawn;
    drawn.reserve(count);
    tr::draw_in_chunks(
        count, seed, sink, [&](Pcg32& rng) { return pair.sample(from, rng); },
        [&](std::span<const double> chunk) { drawn.insert(drawn.end(), chunk.begin(), chunk.end()); });
    return drawn;
  });
  return move_to_array(std::move(values));
}

tr::LawPtr make_const(const std::string& name, const py::kwargs& kwargs) {
  tr::LawSpec spec;
  spec.name = name;
  for (const auto& [key, value] : kwargs) {
    const auto k = key.cast<std::string>();
    if (k == "table") {
      spec.table = path_arg(py::reinterpret_borrow<py::object>(value), "law: table");
    } else if (k == "sampler") {
      if (!py::isinstance<py::str>(value)) throw py::type_error("law: sampler must be a str");
      spec.sampler = value.cast<std::string>();
    } else {
      if (!is_real_number(value))
        throw py::type_error(fmt::format("law {}: parameter {} must be a number, got {}", name, k,
                                         py::str(py::type::of(value)).cast<std::string>()));
      spec.params[k] = py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
    }
  }
  return tr::make_law(spec);
}

PyLaw make(const std::string& name, const py::kwargs& kwargs) { return py_law(make_const(name, kwargs)); }

const char* kArrayDoc =
    "t: a number or array-like of distances >= 0 [length]; returns a float or an array of the same shape.";

}  // namespace

void init_laws(py::module_& m) {
  py::enum_<tr::Origin>(m, "Origin", "Where a free-flight segment starts: at a source/surface (Q) or a scatterer (S).")
      .value("source", tr::Origin::source)
      .value("scatterer", tr::Origin::scatterer);

  py::class_<tr::Law, PyLaw>(m, "Law",
                             "A transmittance law T(t) of free flight (weft/transmittance/law.h). Build one with "
                             "weft.law(name, **parameters).")
      .def_property_readonly("name", &tr::Law::name, "Registry name ('gamma', 'exponential', ...).")
      .def_property_readonly("parameters", &parameters, "The law's parameters (canonical parametrisation) as a dict.")
      .def_property_readonly("sampling_method", &tr::Law::sampling_method, "How sample() draws ('inversion', ...).")
      .def_property_readonly("mean_free_path", &tr::Law::mean_free_path, "l = integral of T over [0, inf).")
      .def(
          "T",
          [](const tr::Law& l, const Array& t) {
            return elementwise("T", t, [&](double x) { return l.transmittance(x); });
          },
          py::arg("t"), (std::string("Transmittance T(t) in [0, 1]. ") + kArrayDoc).c_str())
      .def(
          "log_T",
          [](const tr::Law& l, const Array& t) {
            return elementwise("log_T", t, [&](double x) { return l.log_transmittance(x); });
          },
          py::arg("t"), (std::string("log T(t), accurate where T underflows (-inf where T = 0). ") + kArrayDoc).c_str())
      .def(
          "p", [](const tr::Law& l, const Array& t) { return elementwise("p", t, [&](double x) { return l.pdf(x); }); },
          py::arg("t"), (std::string("Free-flight pdf p(t) = -dT/dt [1/length]. ") + kArrayDoc).c_str())
      .def(
          "sigma",
          [](const tr::Law& l, const Array& t) {
            return elementwise("sigma", t, [&](double x) { return l.hazard(x); });
          },
          py::arg("t"), (std::string("Hazard Sigma(t) = p/T [1/length]. ") + kArrayDoc).c_str())
      .def(
          "sample",
          [](const PyLaw& l, long long n, const std::string& from, std::uint64_t seed, const py::object& progress) {
            const tr::Origin origin = tr::parse_origin(from);
            // As `weft model`: the law is T_Q and its reciprocal partner gives scatterer segments.
            if (origin == tr::Origin::source) return draw(tr::TransmittancePair::same(l), origin, n, seed, progress);
            return draw(tr::TransmittancePair::reciprocal(l, tr::Origin::source), origin, n, seed, progress);
          },
          py::arg("n"), py::arg("from_") = "source", py::arg("seed") = 1, py::kw_only(),
          py::arg("progress") = py::none(),
          "n free-flight distances as a numpy array (+inf for mass that never collides). The law is the\n"
          "source law T_Q; from_='scatterer' draws from its reciprocal partner T_S = p_Q/p_Q(0). Same\n"
          "numbers as `weft model ... --sample n --from FROM --seed SEED`. progress: callback(label, done, total)\n"
          "or None; Ctrl-C stops the draws (KeyboardInterrupt). n * 8 bytes must fit the memory budget.")
      .def("__repr__", [](const tr::Law& l) {
        std::string s = "weft.law('" + l.name() + "'";
        for (const auto& p : l.parameters()) s += fmt::format(", {}={}", p.name, p.value);
        return s + ")";
      });

  m.def("law", &make, py::arg("name"),
        "law(name, **parameters) -> Law\n\n"
        "Builds a registered law by name with its parameter names, e.g.\n"
        "weft.law('gamma', alpha=0.5, mean_extinction=1.0) or weft.law('exponential', mu=2).\n"
        "table='file.csv' for 'tabulated', sampler='inversion' where a law offers several.\n"
        "Raises weft.Error naming a misspelt law or parameter; weft.describe_law(name) lists them.");
  m.def("law_names", &tr::law_names, "The registered law names.");
  m.def("describe_law", &tr::describe_law, py::arg("name"), "The parameters a law accepts, one per line, with units.");

  py::class_<tr::TransmittancePair>(m, "TransmittancePair",
                                    "Source (Q) vs scatterer (S) laws of one medium (Extended GBE, S.21-S.36).")
      .def_static(
          "reciprocal",
          [](const PyLaw& given, const std::string& origin) {
            return tr::TransmittancePair::reciprocal(given, tr::parse_origin(origin));
          },
          py::arg("law"), py::arg("given") = "source",
          "The partner derived by reciprocity p_Q(t) = T_S(t)/l_S; `given` says which side `law` is.")
      .def_static(
          "same", [](const PyLaw& law) { return tr::TransmittancePair::same(law); }, py::arg("law"),
          "T_S = T_Q (the non-reciprocal simplification).")
      .def_static(
          "explicit", [](const PyLaw& q, const PyLaw& s) { return tr::TransmittancePair::explicit_pair(q, s); },
          py::arg("source"), py::arg("scatterer"), "Both laws given.")
      .def_property_readonly("mode", [](const tr::TransmittancePair& p) { return tr::to_string(p.mode()); })
      .def_property_readonly(
          "source", [](const tr::TransmittancePair& p) { return py_law(p.law_ptr(tr::Origin::source)); },
          "The source law T_Q.")
      .def_property_readonly(
          "scatterer", [](const tr::TransmittancePair& p) { return py_law(p.law_ptr(tr::Origin::scatterer)); },
          "The scatterer law T_S.")
      .def(
          "law",
          [](const tr::TransmittancePair& p, const std::string& o) { return py_law(p.law_ptr(tr::parse_origin(o))); },
          py::arg("origin"), "The law of segments from 'source' ('Q') or 'scatterer' ('S').")
      .def(
          "T",
          [](const tr::TransmittancePair& p, const std::string& o, const Array& t) {
            const tr::Law& l = p.law(tr::parse_origin(o));
            return elementwise("T", t, [&](double x) { return l.transmittance(x); });
          },
          py::arg("origin"), py::arg("t"), "T_Q(t) or T_S(t).")
      .def(
          "p",
          [](const tr::TransmittancePair& p, const std::string& o, const Array& t) {
            const tr::Law& l = p.law(tr::parse_origin(o));
            return elementwise("p", t, [&](double x) { return l.pdf(x); });
          },
          py::arg("origin"), py::arg("t"), "p_Q(t) or p_S(t).")
      .def(
          "sample",
          [](const tr::TransmittancePair& p, long long n, const std::string& from, std::uint64_t seed,
             const py::object& progress) { return draw(p, tr::parse_origin(from), n, seed, progress); },
          py::arg("n"), py::arg("from_") = "source", py::arg("seed") = 1, py::kw_only(),
          py::arg("progress") = py::none(), "n free-flight distances for segments from 'source' or 'scatterer'.")
      .def("__repr__", [](const tr::TransmittancePair& p) {
        return fmt::format("<weft.TransmittancePair {}: source {}, scatterer {}>", tr::to_string(p.mode()),
                           p.law(tr::Origin::source).name(), p.law(tr::Origin::scatterer).name());
      });
}

}  // namespace weft::python
