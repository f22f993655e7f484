#include "agglomerate/agglomerate_cli.h"

#include <CLI/CLI.hpp>

namespace rocklab::experiments {

void addAgglomerateCommand(CLI::App& app, AgglomerateOptions& o, bool& no_preview) {
  auto* c = app.add_subcommand(
      "agglomerate",
      "Bonded agglomerates (dense random packing, HCP, or carved by a mesh) -> a library LIB.h5, "
      "LIB.json (porosity, coordination, counts, overlaps, locked-in stress per agglomerate) and "
      "LIB.png (the first one)");
  c->footer(
      "Units are SI (m, Pa). dense: equal spheres of --r-max compacted by the DEM engine in a "
      "servo-controlled spherical wall to --pressure (Hertz-Mindlin, G 70 GPa, nu 0.2, 2700 "
      "kg/m^3, "
      "frictionless and with a normal dashpot of 0.3 while compacting, local damping 0.7; first "
      "with a body "
      "force towards the centre, so that the interior is loaded too), their "
      "count found so that the pack "
      "fills --diameter, then every void filled down to r_max/r0. mesh: a dense agglomerate "
      "larger than the mesh, carved by it (centres inside). Bonds: every pair whose gap is at most "
      "--gap-tolerance x the smaller radius (overlaps included).\n"
      "Examples:\n"
      "  rocklab agglomerate --method dense --r0 4 --count 20 --out lib/dense-r4.h5\n"
      "  rocklab agglomerate --method hcp --diameter 0.042 --angle 30 --out lib/hcp-30.h5\n"
      "  rocklab agglomerate --method mesh --mesh rock.stl --size 0.05 --out lib/rock.h5");
  c->add_option("--method", o.method, "dense | hcp | mesh")->capture_default_str();
  c->add_option("--diameter", o.diameter, "Agglomerate diameter, m (dense, hcp)")
      ->capture_default_str();
  c->add_option("--r-max", o.r_max, "Radius of the loose-pack (dense) or HCP spheres, m")
      ->capture_default_str();
  c->add_option("--r0", o.r0, "Size ratio r_max / r_min (Eq 5-11), dense and mesh")
      ->capture_default_str();
  c->add_option("--angle", o.angle_deg, "HCP rotation about z, degrees in [0, 90]")
      ->capture_default_str();
  c->add_option("--mesh", o.mesh,
                "Mesh method: particle surface (STL, PLY or OBJ; checked as by rocklab shape)");
  c->add_option("--size", o.size,
                "Mesh method: scale the mesh to this size, m (0 = as in the file); see --size-kind")
      ->capture_default_str();
  c->add_option("--size-kind", o.size_kind, "equivalent (equal-volume sphere diameter) | sieve")
      ->capture_default_str();
  c->add_option("--fill-holes", o.fill_holes,
                "Mesh method: close holes of the scan whose rim has at most N edges by a minimum-area patch (0 = none)")
      ->check(CLI::Range(0, 100000));
  c->add_option("--unit", o.unit, "Unit of the mesh file's coordinates: m | mm")
      ->capture_default_str();
  c->add_option("--count", o.count, "Agglomerates to make, seeds --seed, --seed+1, ...")
      ->capture_default_str();
  c->add_option("--seed", o.seed, "Seed of the first agglomerate")->capture_default_str();
  c->add_option("--gap-tolerance", o.gap_tolerance,
                "Bond gap: pairs with gap <= this x the smaller radius are bonded (default 1e-3)");
  c->add_option(
       "--pack", o.pack,
       "Loose pack: servo (DEM compaction in a servo-controlled spherical wall) | geometric "
       "(overlaps pushed apart, no forces)")
      ->capture_default_str();
  c->add_option("--pressure", o.pressure, "Servo target pressure, Pa")->capture_default_str();
  c->add_option("--out", o.out, "Library file to write, LIB.h5 (LIB.json and LIB.png beside it)")
      ->required();
  c->add_flag("--no-preview", no_preview, "Do not render LIB.png");
}

}  // namespace rocklab::experiments
