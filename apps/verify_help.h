// `stereorig verify --help`: what the command does and how it judges
// (the description), and a minimal artifact file of each kind with an
// example (the footer). Written with its line breaks: CLI11 does not wrap a
// description, and the one-line text was ~2960 characters wide.
#pragma once

namespace stereorig {

inline constexpr const char* kVerifyDescription =
    R"(Accuracy of a reconstruction against a reference artifact with certified dimensions, as VDI/VDE 2634
Part 2 defines it: probing error form P_F and size P_S (sphere), sphere-spacing error SD (ball bar),
flatness F (plate). Give one --cloud per position of the artifact; the procedure asks for 7 or more
spread through the volume (fewer keep their verdict, with a note under it). Each figure is judged
against the maximum permissible error (MPE) in the artifact file (mpe_mm; where it gives none, the
default 1.5 mm, and the output says so).

RANSAC locates the artifact; every point within the capture band of it (--capture-band-mm, 5 mm: a
patch one laser-grid period off, ~3.5 mm, stays in) is the artifact's and enters the least-squares
fit and the figures; up to 0.3% of those (the largest residuals) may be excluded, as the standard
allows. What is found must be the artifact: a sphere whose captured points fit a diameter more than
10% off the certified one (or than its locating MPE, P_F or a ball bar's SD, where larger, but
never more than 12.5%, whatever the MPE), or a plane whose dense part (a few stray points do not count) spans less
than half of the plate's length or width or more than the plate plus twice the capture band, is
refused (that position not evaluated, below). Points added by hole filling (PLY module 255) are not
measured and are skipped: the fit never uses the reconstruction's own shape prior. A plate's face
holding two parallel layers in the band is told apart by the cloud's normals (nx ny nz, facing the
measuring module's camera): measured from opposite sides, the smaller is a thin plate's far face, left
out of F (counted in off); from the same side, a module measuring the face off, kept in F (which it
fails); without normals F spans both. A note line says which.

A position whose points or certificate leave a figure (P_S, SD; F, P_F by a large certified flatness
or form uncertainty) undetermined cannot pass: it is not judged (exit 2) when the figure's standard
uncertainty is over 10% of its MPE (a sphere's cap of ~36 deg half-angle at the demo's density fits
its diameter to ~0.15 mm, its neighbouring points' shared noise counted), unless the position fails
beyond doubt anyway (another figure fails, or, under the default simple rule, this one by more than
twice its uncertainty: then FAIL, exit 1; the guarded rules differ, below). A position not judged is
still printed and reported in full, its pass column '-' and a NOT JUDGED line saying why; the
summary takes the judged positions' worst. If a judged position fails, the verdict is FAIL (exit 1)
and the report lists the positions not judged (judged false, pass null, not_judged_reason);
otherwise the verdict is NOT JUDGED and the run exits 2 with the reason on stderr, writing no
report, as for bad input.

A cloud that cannot be read stops the run before anything is printed or written. A cloud read whose
points are not the artifact (too few on it, or none of the certified size, above) is a position not
evaluated: its row shows '-' and its NOT JUDGED line the reason, the other positions are evaluated
and shown all the same, and it counts as a position not judged (report: evaluated false, figures
empty, its counts on the artifact null).

The artifact file's uncertainties are its certificate's expanded ones, U at k = 2 (or its
uncertainty_coverage_factor): U / k enters P_S (diameter), SD (centre distance) and F (flatness) in
quadrature with the fit's, and the rules above read the combined u. A sphere's form_uncertainty_mm
(the U of its certified form) is P_F's, as a plate's flatness_uncertainty_mm is F's.

--decision-rule says how a figure and its expanded uncertainty 2u are judged against the MPE (ISO
14253-1: the uncertainty counts against whoever must prove a claim; the rules as ILAC-G8 names
them): simple (default, as earlier builds: pass if |value| <= MPE, u not used), guarded-acceptance
(pass only if |value| + 2u <= MPE; for whoever must show the rig conforms, e.g. a supplier at
delivery) or guarded-rejection (fail only if |value| - 2u > MPE; for whoever must show it does not).

Each figure's zone (conformance, uncertainty range, nonconformance) is printed and reported for
every judged figure that has a u, whatever the rule; u is the fit's covariance and the
certificate's, a floor rather than the whole error. A figure without u (P_F or F against an exact
certificate) has no zone, and every rule judges it with 2u = 0. A figure whose u is over 10% of its
MPE is judged only where its failure stands: under simple acceptance, which reads the value
alone, when the value is beyond the MPE by more than its stated 2u; under guarded-acceptance any
failure (a larger u only widens the guard band); under guarded-rejection when it is beyond the MPE
by more than 2u and u is over the limit by the certificate's stated U (not where the fit's own part
is over it: that u is a floor, and a larger one could undo the failure). Otherwise it is shown with
'-' in the pass column, and with no zone where its u is a floor.

The table gives, per position, each figure's standard uncertainty (u_mm; both parts on a line of
their own), the points in the cloud and where each of them went, in exactly one column: filled
(skipped), off (not the artifact's: outside the capture band, in a ball bar's shaft cone, off a
plate's outline or on its far face), edge (in a plate's 5 mm edge margin), excluded and used; per sphere its diameter,
the diameter's standard uncertainty, the half-angle of the cap its points cover and its form (the
range of its residuals; on a ball bar reported, not judged: a patch one grid period off on one ball
shows there); per plate the outline of its face's dense part.

Exit codes: 0 every figure passes; 1 a figure of a judged position fails (under the decision rule);
2 bad input, or a position not judged or not evaluated (and none failed).
)";

inline constexpr const char* kVerifyFooter =
    R"(Artifact files (YAML, mm; docs/verify-and-check.md; examples in datasets/artifacts/). The keys each
kind requires; *_uncertainty_mm (the certificate's expanded U, default 0), uncertainty_coverage_factor
(its k, default 2), name (default: the file's stem) and mpe_mm (default 1.5 mm each) are optional:

  format: stereorig-artifact        format: stereorig-artifact        format: stereorig-artifact
  version: 1                        version: 1                        version: 1
  units: mm                         units: mm                         units: mm
  type: sphere                      type: ballbar                     type: plate
  diameter_mm: 38.1                 sphere_diameter_mm: 25.4          length_mm: 130
  mpe_mm: {P_F: 1.5, P_S: 1.5}      center_distance_mm: 80            width_mm: 120
                                    mpe_mm: {SD: 1.5}                 mpe_mm: {F: 1.5}

Example:
  stereorig verify --artifact datasets/artifacts/sphere_38mm.yaml --cloud sphere_pos1.ply \
      --cloud sphere_pos2.ply --report verify.json)";

}  // namespace stereorig
