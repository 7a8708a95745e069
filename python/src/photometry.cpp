// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/photometry.cpp — far-field photometry (IES LM-63, EULUMDAT): lumx.read_photometry, the
// Photometry class with its stored table as NumPy views, intensity queries, datasheet figures, writing;
// lumx.check for photometry files, raysets and bundles.
#include "common.h"

#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/polar_diagram.h>
#include <lumx/photometry/ugr.h>
#include <lumx/photometry/validate.h>

#include <cctype>
#include <filesystem>
#include <memory>

namespace lumx_py {

namespace {

// A NumPy view of `values` whose base is the Photometry's Python object, so the array keeps it alive.
// Writable: edits change the photometry (every query builds its table from the current values).
py::array view(std::vector<double>& values, std::vector<py::ssize_t> shape, py::handle owner) {
  std::vector<py::ssize_t> strides(shape.size(), py::ssize_t(sizeof(double)));
  for (std::size_t i = shape.size(); i-- > 1;) strides[i - 1] = strides[i] * shape[i];
  return py::array(py::dtype::of<double>(), shape, strides, values.data(), owner);
}

lumx::SpreadPlane plane_from(const std::string& name) {
  if (name == "C0-C180" || name == "c0_c180") return lumx::SpreadPlane::c0_c180;
  if (name == "C90-C270" || name == "c90_c270") return lumx::SpreadPlane::c90_c270;
  throw py::value_error("plane: expected 'C0-C180' or 'C90-C270', got '" + name + "'");
}

// The table every query uses; built while the GIL is held (the candela views may be edited meanwhile).
lumx::IntensityTable table_of(const lumx::Photometry& p) {
  return lumx::IntensityTable(p);
}

bool is_rayset_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return false;
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".ies" || ext == ".ldt") return false;
  if (ext == ".tm25ray" || ext == ".ray") return true;
  return lumx::detect_rayset_format(path).has_value();
}

}  // namespace

void bind_photometry(py::module_& m) {
  py::class_<lumx::Spread>(m, "Spread", "Beam (50 %) and field (10 %) angles of one vertical plane.")
      .def_readonly("beam_deg", &lumx::Spread::beam_deg, "full beam angle, degrees (360: never falls to 50 %)")
      .def_readonly("field_deg", &lumx::Spread::field_deg, "full field angle, degrees (360: never falls to 10 %)")
      .def_readonly("peak_cd", &lumx::Spread::peak_cd, "largest intensity in the plane, cd")
      .def_readonly("peak_angle_deg", &lumx::Spread::peak_angle_deg,
                    "signed angle of the peak from nadir, degrees (+ towards C0 or C90)")
      .def("__repr__", [](const lumx::Spread& s) {
        return "<lumx.Spread beam " + std::to_string(s.beam_deg) + " deg, field " + std::to_string(s.field_deg) +
               " deg>";
      });

  py::class_<lumx::PhotometricSummary>(m, "Summary", "The datasheet figures of a photometry (what `lumx info` prints).")
      .def_readonly("flux_lm", &lumx::PhotometricSummary::flux_lm, "luminaire flux, lm (exact integral of the table)")
      .def_readonly("rated_lamp_flux_lm", &lumx::PhotometricSummary::rated_lamp_flux_lm,
                    "sum of the lamp sets' rated flux, lm (0 for absolute photometry)")
      .def_readonly("max_cd", &lumx::PhotometricSummary::max_cd, "largest tabulated intensity, cd")
      .def_readonly("max_horizontal_deg", &lumx::PhotometricSummary::max_horizontal_deg,
                    "horizontal angle of the tabulated peak, degrees")
      .def_readonly("max_vertical_deg", &lumx::PhotometricSummary::max_vertical_deg,
                    "vertical angle of the tabulated peak, degrees")
      .def_readonly("c0_c180", &lumx::PhotometricSummary::c0_c180, "spread in the C0-C180 plane")
      .def_readonly("c90_c270", &lumx::PhotometricSummary::c90_c270, "spread in the C90-C270 plane")
      .def_readonly("downward_fraction", &lumx::PhotometricSummary::downward_fraction,
                    "fraction of the flux emitted downwards, 0..1")
      .def_readonly("light_output_ratio", &lumx::PhotometricSummary::light_output_ratio,
                    "flux / rated lamp flux, or None for absolute photometry")
      .def_readonly("efficacy_lm_per_w", &lumx::PhotometricSummary::efficacy_lm_per_w,
                    "flux / input watts, lm/W (0 when the watts are unknown)");

  py::class_<lumx::LampSet>(m, "LampSet", "One set of lamps as the file states it.")
      .def_readonly("count", &lumx::LampSet::count, "number of lamps (EULUMDAT: negative for absolute photometry)")
      .def_readonly("type", &lumx::LampSet::type)
      .def_readonly("flux_lm", &lumx::LampSet::flux_lm, "total rated flux of the set, lm")
      .def_readonly("color", &lumx::LampSet::color)
      .def_readonly("cri", &lumx::LampSet::cri)
      .def_readonly("watts", &lumx::LampSet::watts, "wattage including ballast, W");

  py::class_<lumx::Photometry>(m, "Photometry",
                               "Far-field photometry (IES LM-63 or EULUMDAT): the stored part of the intensity "
                               "table (cd) over horizontal and vertical angles (degrees), its symmetry, lamps "
                               "and descriptive data. Frame: +X = C0, +Y = C90, -Z = nadir; lengths in m.")
      .def_property_readonly(
          "type", [](const lumx::Photometry& p) { return lumx::to_string(p.type); },
          "photometric type: 'C', 'B' or 'A'")
      .def_property_readonly(
          "symmetry", [](const lumx::Photometry& p) { return lumx::to_string(p.symmetry); },
          "which part of the sphere is stored; the rest follows by mirroring")
      .def_property_readonly(
          "horizontal_deg",
          [](py::object self) {
            auto& p = self.cast<lumx::Photometry&>();
            return view(p.horizontal_deg, {py::ssize_t(p.horizontal_deg.size())}, self);
          },
          "stored horizontal angles (C for Type C, H for A/B), degrees: a view (no copy) of the table")
      .def_property_readonly(
          "vertical_deg",
          [](py::object self) {
            auto& p = self.cast<lumx::Photometry&>();
            return view(p.vertical_deg, {py::ssize_t(p.vertical_deg.size())}, self);
          },
          "stored vertical angles (gamma for Type C, V for A/B), degrees: a view (no copy)")
      .def_property_readonly(
          "candela",
          [](py::object self) {
            auto& p = self.cast<lumx::Photometry&>();
            return view(p.candela, {py::ssize_t(p.horizontal_deg.size()), py::ssize_t(p.vertical_deg.size())}, self);
          },
          "stored intensities, cd, shape (len(horizontal_deg), len(vertical_deg)): a view (no copy) of the "
          "table; the file's multiplier is already applied")
      .def_property_readonly(
          "flux_lm",
          [](const lumx::Photometry& p) {
            const lumx::IntensityTable t = table_of(p);
            return t.flux_lm();
          },
          "luminous flux, lm: the exact integral of the bilinear full-sphere table")
      .def(
          "intensity",
          [](const lumx::Photometry& p, const py::object& directions) {
            const Vec3Rows d = vec3_rows(directions, "directions");
            const lumx::IntensityTable t = table_of(p);
            py::array_t<double> out(py::ssize_t(d.count));
            double* o = out.mutable_data();
            {
              py::gil_scoped_release release;
              for (std::size_t i = 0; i < d.count; ++i) o[i] = t.intensity(d.at(i));
            }
            return scalar_or_array(out, d.single);
          },
          py::arg("directions"),
          "Intensity, cd, towards each direction of an (N, 3) array (unit or not; photometric frame): an (N,) "
          "array, or a float for one (3,) vector. Bilinear in the full-sphere table.")
      .def(
          "intensity_at",
          [](const lumx::Photometry& p, const py::object& horizontal_deg, const py::object& vertical_deg) {
            DoubleArray h = DoubleArray::ensure(horizontal_deg), v = DoubleArray::ensure(vertical_deg);
            if (!h || !v) throw py::value_error("intensity_at: expected arrays of angles in degrees");
            py::array_t<double> out;
            {
              auto hb = h.request(), vb = v.request();
              if (hb.size != vb.size) throw py::value_error("intensity_at: the two angle arrays differ in size");
              out = py::array_t<double>(hb.shape);
              const lumx::IntensityTable t = table_of(p);
              double* o = out.mutable_data();
              const double *hp = h.data(), *vp = v.data();
              py::gil_scoped_release release;
              for (py::ssize_t i = 0; i < hb.size; ++i) o[i] = t.at_angles(hp[i], vp[i]);
            }
            if (out.ndim() == 0) return py::object(py::float_(*out.data()));
            return py::object(out);
          },
          py::arg("horizontal_deg"), py::arg("vertical_deg"),
          "Intensity, cd, at photometric angles of the photometry's own type, degrees: (C, gamma) for Type C, "
          "(H, V) for A and B. Arrays of one shape in, that shape out.")
      .def(
          "polar_curve",
          [](const lumx::Photometry& p, const std::string& plane, double step_deg) {
            const lumx::IntensityTable t = table_of(p);
            const std::vector<lumx::PolarPoint> pts = lumx::sample_polar_plane(t, plane_from(plane), 1.0, step_deg);
            py::array_t<double> theta(py::ssize_t(pts.size())), cd(py::ssize_t(pts.size()));
            for (std::size_t i = 0; i < pts.size(); ++i) {
              theta.mutable_at(py::ssize_t(i)) = pts[i].angle_deg;
              cd.mutable_at(py::ssize_t(i)) = pts[i].value;
            }
            return py::make_tuple(theta, cd);
          },
          py::arg("plane") = "C0-C180", py::arg("step_deg") = 0.5,
          "One vertical plane as a polar curve, as `lumx plot` draws it: (theta_deg, cd), theta from -180 to "
          "180 degrees from nadir (+ towards C0 or C90), intensities in cd.")
      .def(
          "summary",
          [](const lumx::Photometry& p) {
            const lumx::Photometry copy = p;
            py::gil_scoped_release release;
            return lumx::summarize(copy);
          },
          "Datasheet figures: flux (lm), peak (cd), beam and field angles per plane (degrees), downward "
          "fraction, light output ratio, efficacy (lm/W) — the numbers `lumx info` prints.")
      .def(
          "ugr_table",
          [](const lumx::Photometry& p, double spacing_to_height, double height_m) {
            lumx::UgrTableOptions o;
            o.spacing_to_height = spacing_to_height;
            o.height_m = height_m;
            lumx::UgrTable t;
            {
              const lumx::Photometry copy = p;
              py::gil_scoped_release release;
              t = lumx::ugr_table(copy, o);
            }
            const std::size_t rooms = o.rooms.size(), refl = o.reflectances.size();
            py::array_t<double> cross({rooms, refl}), end({rooms, refl}), room_xy({rooms, std::size_t(2)}),
                cwf({refl, std::size_t(3)});
            for (std::size_t i = 0; i < rooms; ++i) {
              room_xy.mutable_at(i, 0) = o.rooms[i].x_h;
              room_xy.mutable_at(i, 1) = o.rooms[i].y_h;
              for (std::size_t k = 0; k < refl; ++k) {
                cross.mutable_at(i, k) = t.at(i, k, lumx::UgrView::crosswise);
                end.mutable_at(i, k) = t.at(i, k, lumx::UgrView::endwise);
              }
            }
            for (std::size_t k = 0; k < refl; ++k) {
              cwf.mutable_at(k, 0) = o.reflectances[k].ceiling;
              cwf.mutable_at(k, 1) = o.reflectances[k].walls;
              cwf.mutable_at(k, 2) = o.reflectances[k].floor;
            }
            py::dict d;
            d["crosswise"] = cross;
            d["endwise"] = end;
            d["rooms_xy_h"] = room_xy;
            d["reflectances_cwf"] = cwf;
            d["luminaire_flux_lm"] = t.luminaire_flux_lm;
            return d;
          },
          py::kw_only(), py::arg("spacing_to_height") = 0.25, py::arg("height_m") = 2.0,
          "The UGR table by the CIE 117/190 tabular method, as `lumx info --json` gives it: a dict of "
          "'crosswise' and 'endwise' (19 rooms × 5 reflectances, NaN where no luminaire is in view), "
          "'rooms_xy_h' (X, Y in multiples of H), 'reflectances_cwf' (ceiling, walls, floor) and "
          "'luminaire_flux_lm'. spacing_to_height 0.25 is the catalogues' convention (CIE 190's own example "
          "uses 1.0); height_m is H, the luminaire plane above the eye. Raises lumx.Error when the file gives "
          "no luminous area.")
      .def(
          "validate", [](const lumx::Photometry& p) { return lumx::validate(p); },
          "Findings of strict validation (a list of lumx.Finding), located by the source lines when known.")
      .def(
          "write",
          [](const lumx::Photometry& p, const std::string& path, int ies_version, int digits, bool expand_c90_c270) {
            lumx::WriteOptions o;
            if (ies_version != 2002 && ies_version != 2019) throw py::value_error("ies_version: 2002 or 2019");
            o.ies.version = ies_version == 2002 ? lumx::IesVersion::lm63_2002 : lumx::IesVersion::lm63_2019;
            o.ies.significant_digits = o.ldt.significant_digits = digits;
            o.ies.expand_c90_c270 = expand_c90_c270;
            const lumx::Photometry copy = p;
            py::gil_scoped_release release;
            lumx::write_photometry(copy, path, o);
          },
          py::arg("path"), py::arg("ies_version") = 2019, py::arg("digits") = 7, py::arg("expand_c90_c270") = false,
          "Writes the photometry as IES (.ies) or EULUMDAT (.ldt, Type C only) by the extension of `path`, "
          "atomically (a temporary file renamed over it). `digits`: significant digits of angles and cd.")
      .def_readonly("absolute", &lumx::Photometry::absolute, "absolute photometry (no rated lamp flux)")
      .def_readonly("lamps", &lumx::Photometry::lamp_sets, "the lamp sets (list of lumx.LampSet)")
      .def_readonly("ballast_factor", &lumx::Photometry::ballast_factor, "as stated; never applied to the table")
      .def_readonly("input_watts", &lumx::Photometry::input_watts, "luminaire input power, W")
      .def_property_readonly(
          "keywords",
          [](const lumx::Photometry& p) {
            py::list out;
            for (const lumx::Keyword& k : p.keywords) out.append(py::make_tuple(k.name, k.value));
            return out;
          },
          "IES keywords in file order, as (name, value) pairs; names without brackets")
      .def_property_readonly(
          "opening",
          [](const lumx::Photometry& p) {
            py::dict d;
            d["width_m"] = p.opening.width_m;
            d["length_m"] = p.opening.length_m;
            d["height_m"] = p.opening.height_m;
            d["shape"] = lumx::to_string(p.opening.shape());
            return d;
          },
          "the luminous opening: signed width (along C90), length (along C0) and height, m, and its shape")
      .def_property_readonly("file", [](const lumx::Photometry& p) { return p.source.file; })
      .def_property_readonly(
          "format", [](const lumx::Photometry& p) { return p.source.format; }, "'IES' or 'EULUMDAT'")
      .def_property_readonly(
          "version", [](const lumx::Photometry& p) { return p.source.version; }, "e.g. 'LM-63-2002'")
      .def("__repr__", [](const lumx::Photometry& p) {
        return "<lumx.Photometry " + p.source.format + " type " + lumx::to_string(p.type) + ", " +
               std::to_string(p.horizontal_deg.size()) + " x " + std::to_string(p.vertical_deg.size()) + " angles, '" +
               p.source.file + "'>";
      });

  m.def(
      "read_photometry",
      [](const std::string& path) {
        WarningCollector warnings;
        std::unique_ptr<lumx::Photometry> p;
        {
          lumx::ReadOptions o;
          o.warnings = warnings.sink();
          py::gil_scoped_release release;
          p = std::make_unique<lumx::Photometry>(lumx::read_photometry(path, o));
        }
        warnings.emit();
        return p;
      },
      py::arg("path"),
      "Reads an IES LM-63 (1986-2019) or EULUMDAT file (format by extension, else by content). Raises "
      "lumx.Error located at file, line and field for malformed data, OSError when the file cannot be read; "
      "the reader's warnings are issued as lumx.LumxWarning.");

  m.def(
      "check",
      [](const std::string& path) {
        std::string ext = std::filesystem::path(path).extension().string();
        for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
        if (ext == ".glb" || ext == ".gltf")
          throw py::value_error(path +
                                ": glTF luminaires are checked by the bake component (`lumx check`), which "
                                "this module does not include");
        std::vector<lumx::Diagnostic> findings;
        {
          py::gil_scoped_release release;
          std::error_code ec;
          try {
            if (std::filesystem::is_directory(path, ec)) {
              findings = lumx::check_bundle(path);
            } else if (is_rayset_file(path)) {
              lumx::RaysetReadOptions o;
              o.warnings = [&findings](const lumx::Diagnostic& d) { findings.push_back(d); };
              std::unique_ptr<lumx::RaySource> src = lumx::open_rayset(path, o);
              lumx::RayChunk c;
              while (src->next(c, o.chunk_rays)) {
              }
            } else {
              lumx::ReadOptions o;
              o.warnings = [&findings](const lumx::Diagnostic& d) { findings.push_back(d); };
              const lumx::Photometry p = lumx::read_photometry(path, o);
              for (auto& d : lumx::validate(p)) findings.push_back(d);
            }
          } catch (const lumx::Error& e) {
            findings.push_back(e.diagnostic());
          } catch (const std::exception& e) {  // e.g. out of memory: a finding of this file, as `lumx check` has it
            findings.push_back(lumx::Diagnostic{lumx::Severity::error, path, 0, -1, "file", e.what()});
          }
        }
        for (auto& d : findings)
          if (d.file.empty()) d.file = path;
        return findings;
      },
      py::arg("path"),
      "Checks a photometry file, a rayset (every ray read) or a bundle folder (every payload, checksums, "
      "flux across levels) as `lumx check` does, and returns the findings: a list of lumx.Finding with "
      "file, line, byte_offset, field, message and severity. Empty means OK. Never raises for bad content.");
}

}  // namespace lumx_py
