// The scene reference: one documentation line per key (adding a key to a
// reader = adding its line here, in the table's group), the coverage scenes
// that reach every reader branch, and the Markdown of docs/scene-format.md.
#include "scene/scene_keys.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <unistd.h>

#include "agglomerate/agglomerate_library.h"
#include "common/joined_text.h"
#include "rocklab/experiments/scene.h"
#include "scene/toml_reader.h"

namespace rocklab::experiments {

const std::vector<KeyDoc>& sceneKeyDocs() {
  // {table, key, unit, text, values (optional), default (optional)}; key "" = the table.
  static const std::vector<KeyDoc> docs = {
      // --- top level
      {"", "scene", "", "[scene]: what the run is called and when it ends (required)."},
      {"", "materials", "", "[materials.NAME]: the materials balls and walls refer to (at least one)."},
      {"", "contact", "", "[contact]: the contact law and its damping."},
      {"", "gravity", "", "[gravity]: gravity and its changes in time."},
      {"", "timestep", "", "[timestep]: how the time step is chosen."},
      {"", "neighbours", "", "[neighbours]: the neighbour search."},
      {"", "watchdog", "", "[watchdog]: the stability checks that stop a run."},
      {"", "relaxation", "", "[relaxation]: easing apart the overlaps a scene starts with."},
      {"", "walls", "", "[[walls]]: the walls, one table each."},
      {"", "crusher", "", "[crusher]: a cone crusher's chamber and mantle motion (docs/crusher.md)."},
      {"", "particles", "", "[[particles]]: the particle sources, one table each."},
      {"", "bonds", "", "[bonds]: the parallel bonds of the agglomerates (required with agglomerates)."},
      {"", "cameras", "", "[[cameras]]: virtual cameras that film the run."},
      {"", "experiment", "", "[experiment]: the laboratory procedure that drives the run; none = a plain run."},
      {"", "output", "", "[output]: what the run writes."},

      // --- [scene]
      {"scene", "", "", "What the run is called and how long it lasts. Give exactly one of end_time and steps."},
      {"scene", "name", "", "Name of the run; the default output folder is out/NAME, so a plain folder name: not empty, no / or \\\\, not . or .., no control characters, at most 100 characters."},
      {"scene", "description", "", "One line shown by `rocklab list`."},
      {"scene", "seed", "", "Seed of every random choice (insertion, orientations, bond strengths); equal seeds give equal runs."},
      {"scene", "end_time", "s", "Simulated time at which the run ends (an experiment may end it earlier); 0 = use steps."},
      {"scene", "steps", "", "Number of steps after which the run ends; 0 = use end_time."},

      // --- [materials.NAME]
      {"materials", "", "", "One sub-table per material, [materials.NAME]; walls and particle sources name it with `material`."},
      {"materials.NAME", "", "", "One material. Stiffnesses are per entity: a contact puts the two entities' springs in series (docs/models.md)."},
      {"materials.NAME", "colour", "", "Colour [r, g, b] of balls of this material in images, channels in [0, 1].", "[r, g, b], each in [0, 1]", "[0.56, 0.55, 0.52] (grey pebble)"},
      {"materials.NAME", "density", "kg/m^3", "Density of the balls (walls ignore it)."},
      {"materials.NAME", "kn", "N/m", "Normal stiffness of this entity (linear law, Eq 2-20)."},
      {"materials.NAME", "ks", "N/m", "Shear stiffness of this entity (linear law, Eq 2-21).", nullptr, "kn"},
      {"materials.NAME", "friction", "", "Coulomb friction coefficient; a contact uses the smaller of its two entities' (Eq 2-39)."},
      {"materials.NAME", "shear_modulus", "Pa", "Shear modulus G (Hertz-Mindlin law, Eq 2-22; required > 0 with that law)."},
      {"materials.NAME", "poisson", "", "Poisson's ratio (Hertz-Mindlin law)."},

      // --- [contact]
      {"contact", "", "", "The contact law of every ball-ball and ball-wall contact, its damping, and a stiffness scale."},
      {"contact", "law", "", "Contact law: linear springs in series, or the study's simplified Hertz-Mindlin."},
      {"contact", "damping_normal", "", "Critical damping ratio beta of the normal dashpot (Eq 2-17)."},
      {"contact", "damping_shear", "", "Critical damping ratio of the shear dashpot.", nullptr, "damping_normal"},
      {"contact", "damping_mass", "", "Mass of a ball-ball dashpot: the study's average of the two masses, or the reduced mass."},
      {"contact", "friction_rule", "", "Friction of a contact between two materials (ball-ball and ball-wall): the smaller of the two (the study's Eq 2-39), the larger (a base measured against the pebbles acts at its own value), or the mean."},
      {"contact", "local_damping", "", "Cundall's local damping alpha (Eq 2-15, sign form); 0 = off."},
      {"contact", "stiffness_scale", "", "Factor on every material's kn, ks and shear_modulus (one key for a stiffness study)."},

      // --- [gravity]
      {"gravity", "", "", "Gravity at t = 0 and a schedule of changes (a chute experiment turns gravity itself)."},
      {"gravity", "vector", "m/s^2", "Gravity at the start."},
      {"gravity", "change", "", "[[gravity.change]]: gravity switches to `vector` at `time`."},
      {"gravity.change", "", "", "One change of gravity; changes in increasing time order."},
      {"gravity.change", "time", "s", "When gravity switches."},
      {"gravity.change", "vector", "m/s^2", "Gravity from then on."},

      // --- [timestep]
      {"timestep", "", "", "The step is safety_factor x the critical step of the time-step audit (docs/models.md), lowered further by the damped cap."},
      {"timestep", "safety_factor", "", "Fraction of the critical step used."},
      {"timestep", "dt", "s", "Requested step; 0 = automatic. It may only lower the automatic step (unless allow_unsafe)."},
      {"timestep", "impact_velocity", "m/s", "Impact speed of the Hertz contact-time line of the audit."},
      {"timestep", "allow_unsafe", "", "Accept a dt above the automatic one (stability tests; the network check then runs every check_interval steps)."},

      // --- [neighbours]
      {"neighbours", "", "", "Verlet lists on a multi-level grid."},
      {"neighbours", "skin", "m", "Verlet skin; 0 = 0.2 x the mean ball radius."},
      {"neighbours", "max_levels", "", "Grid levels (one per doubling of the radius); 1 = one plain grid."},

      // --- [watchdog]
      {"watchdog", "", "", "Stops a run that blows up, naming the particle, the time and the setting to change (exit code 3)."},
      {"watchdog", "max_overlap_fraction", "", "Overlap, as a fraction of the smaller radius, that stops the run (checked every step)."},
      {"watchdog", "max_energy_growth", "", "Allowed rise of mechanical energy beyond the work of moving walls, fraction of its scale."},
      {"watchdog", "check_interval", "", "Steps between energy checks (the overlap is checked every step, the energy also at every observed step)."},
      {"watchdog", "network_iterations", "", "Power iterations of the contact-network step check; 0 = off."},
      {"watchdog", "network_interval", "", "Steps between contact-network step checks."},

      // --- [relaxation]
      {"relaxation", "", "", "Initial overlaps kept as offsets that shrink to zero, so overlapping bodies are eased apart."},
      {"relaxation", "steps", "", "Steps over which the initial overlaps are relaxed; 0 = off."},

      // --- [crusher]
      {"crusher", "", "", "Cone crusher of experiments.md §g (Table 6.1; the baseline by default). Adds its walls as mesh walls crusher.mantle and .mantle_cap (gyrating about the crusher axis and spinning by Eq 6-9), .lower_concave, .upper_concave (static); `rocklab crusher-geometry SCENE` prints the derived chamber (docs/crusher.md)."},
      {"crusher", "feed_opening", "m", "F: width of the chamber's feed opening; must exceed css."},
      {"crusher", "css", "m", "CSS: closed-side setting, the nominal smallest mantle-concave gap; below feed_opening."},
      {"crusher", "throw", "m", "s: eccentric travel of the cone in half a revolution."},
      {"crusher", "bite_angle_deg", "deg", "beta: angle between the upper concave and the mantle."},
      {"crusher", "cone_angle_deg", "deg", "alpha: cone angle at the base of the mantle."},
      {"crusher", "eccentric_angle_deg", "deg", "gamma: tilt of the mantle axis (below cone_angle_deg)."},
      {"crusher", "parallel_length", "m", "delta_l: length of the lower concave, parallel to the mantle at the CSS position."},
      {"crusher", "mantle_diameter", "m", "D_c: bottom diameter of the mantle."},
      {"crusher", "mantle_top_x", "", "x of the mantle's top centre O_top_m: the [R]-corrected R_top_c - F sin(alpha-gamma) - cos(gamma) R_top_m, or as printed (without the F term)."},
      {"crusher", "pivot", "", "The [X] pivot reading: axis = (A) Eq 6-2..6-8 as printed, pivot at s/sin(gamma) on the crusher axis; eq6-1 = (B) Eq 6-1's h with the mantle's bottom centre s/2 off the axis."},
      {"crusher", "segments", "", "Triangles around each frustum wall (x 2 for a frustum): the mesh resolution."},
      {"crusher", "eccentric_speed_rpm", "rpm", "Gyration speed omega_ecc of the mantle about the crusher axis; the spin follows by Eq 6-9."},
      {"crusher", "spin_sense", "", "Spin of the mantle about its own axis: opposite to the gyration (rolls on the feed at the closed side), same, or none."},
      {"crusher", "material", "", "Material of the crusher walls.", "a name under [materials]"},
      {"crusher", "walls", "", "Add the chamber walls (mantle, cap, lower and upper concave) to the scene's walls."},
      {"crusher", "feed_bin", "", "Add §g.4's temporary walls: the feed-bin cylinder crusher.feed_bin above the chamber and the flat stop wall crusher.stop the feed rests on until release_time."},
      {"crusher", "feed_bin_radius", "m", "Radius of the feed-bin cylinder (below R_top_c, so the feed falls into the chamber)."},
      {"crusher", "stop_height", "m", "Height of the stop wall and the feed bin's bottom (above the chamber's top).", nullptr, "10 mm above O_top_c"},
      {"crusher", "feed_bin_top", "m", "Height of the feed bin's top.", nullptr, "stop_height + 0.5 m"},
      {"crusher", "release_time", "s", "When the stop wall goes and the feed falls into the chamber."},
      {"crusher", "mantle_colour", "", "Colour [r, g, b] of the mantle and its cap in images (the feed bin and the stop wall are a dark steel, [0.34, 0.36, 0.38]).", "[r, g, b], each in [0, 1]", "[0.30, 0.42, 0.62] (blue steel)"},
      {"crusher", "concave_colour", "", "Colour [r, g, b] of the lower and upper concave in images.", "[r, g, b], each in [0, 1]", "[0.66, 0.50, 0.30] (bronze)"},

      // --- [[walls]]
      {"walls", "", "", "A wall: plane, polygon, plate, mesh or box, with prescribed motion and an active time window. Keys by type are marked (plane), (polygon), ..."},
      {"walls", "type", "", "Shape of the wall. A box makes five or six planes named NAME.floor, .xmin, .xmax, .ymin, .ymax, .top."},
      {"walls", "name", "", "Name, for experiment keys and --set walls.NAME.KEY=...", nullptr, "walls.INDEX"},
      {"walls", "material", "", "Material of the wall.", "a name under [materials]"},
      {"walls", "active_from", "s", "The wall exists from this time on.", nullptr, "-inf (always)"},
      {"walls", "active_until", "s", "The wall is removed at this time (a gate).", nullptr, "inf (never)"},
      {"walls", "motion", "", "[walls.motion]: prescribed motion."},
      {"walls", "point", "m", "(plane) A point of the plane."},
      {"walls", "normal", "", "(plane) Normal pointing to where the balls are (need not be unit)."},
      {"walls", "vertices", "m", "(polygon) Convex planar polygon, vertices in order; (mesh) vertices of the triangles."},
      {"walls", "corner", "m", "(plate) Corner of the rectangle."},
      {"walls", "length", "m", "(plate) Side along x, turned up by angle_deg about y."},
      {"walls", "width", "m", "(plate) Side along y."},
      {"walls", "angle_deg", "deg", "(plate) Angle of the length side above the x axis."},
      {"walls", "file", "", "(mesh) STL, PLY or OBJ file, relative to the scene file."},
      {"walls", "scale", "", "(mesh) Factor on the coordinates (0.001 for a file in mm)."},
      {"walls", "offset", "m", "(mesh) Added to every vertex after the scale: places a file's part in the scene, or moves a mesh with one key (the heap funnel's height)."},
      {"walls", "triangles", "", "(mesh) Triangles as vertex indices [[i, j, k], ...] (whole numbers from 0, each below the vertex count), without `file`."},
      {"walls", "smooth_angle_deg", "deg", "(mesh) Faces meeting at less than this angle are one smooth surface (a curved wall's tessellation): a ball touching two of them has one contact, the nearer face's. Sharper concave creases are corners, each face its own contact (the far face from its edge on); 0 = the nearer face shadows the far one's edge at any crease."},
      {"walls", "min", "m", "(box) Lower corner."},
      {"walls", "max", "m", "(box) Upper corner."},
      {"walls", "open_top", "", "(box) Leave out the top face."},
      {"walls", "colour", "", "Colour [r, g, b] in images.", "[r, g, b], each in [0, 1]", "[0.45, 0.45, 0.47]"},
      {"walls", "opacity", "", "Opacity in images; < 1 is transparent (the Perspex the lab filmed through)."},
      {"walls", "visible", "", "Draw the wall in images."},
      {"walls", "plane_size", "m", "Side (square) or diameter (disc) of the shape drawn for an infinite plane."},
      {"walls", "plane_shape", "", "How an infinite plane is drawn around its point: a square or a disc."},
      {"walls", "plane_thickness", "m", "Draw the plane as a solid slab of this thickness behind it (a platen seen edge-on); 0 = flat."},
      {"walls.motion", "", "", "x(t) = pivot + velocity t + amplitude sin(2 pi frequency t) + R(angular_velocity t) (x0 - pivot)."},
      {"walls.motion", "velocity", "m/s", "Constant translation velocity."},
      {"walls.motion", "angular_velocity", "rad/s", "Constant angular velocity about the pivot (not for infinite planes)."},
      {"walls.motion", "pivot", "m", "Centre of the rotation."},
      {"walls.motion", "amplitude", "m", "Amplitude of a sinusoidal oscillation."},
      {"walls.motion", "frequency", "Hz", "Frequency of the oscillation; 0 = none."},

      // --- [[particles]]
      {"particles", "", "", "A source of spheres or clumps (lattice, random or list), one bonded agglomerate, or a feed of them (agglomerates). Keys by type or shape are marked."},
      {"particles", "type", "", "How the bodies are placed: a lattice, random non-overlapping insertion, a list of positions, an agglomerate, or agglomerates at random in a box (§g.7's bonded feed)."},
      {"particles", "material", "", "Material of the balls.", "a name under [materials]"},
      {"particles", "velocity", "m/s", "Initial velocity of every body (list: unless `velocities`)."},
      {"particles", "shape", "", "Body shape: a sphere, the study's four-ball clump, or a clump file (x y z r per line)."},
      {"particles", "radius", "m", "Sphere radius (lattice, list; random: or radius_min/radius_max); (agglomerate hcp) sphere radius; (agglomerate dense) r_max, the loose pack's radius; (agglomerates) the same at diameter_max, scaled with each agglomerate's diameter.", nullptr, "required (see text)"},
      {"particles", "radius_min", "m", "(random) Smallest radius; radii uniform in [radius_min, radius_max]."},
      {"particles", "radius_max", "m", "(random) Largest radius."},
      {"particles", "diameters_file", "", "(random) Spheres of these sizes instead of radius or radius_min/radius_max and count: a CSV, relative to the scene, whose first line names a diameter_mm (or diameter_m) column, one sphere a row (a crusher run's product.csv as it is).", nullptr, "none: radius or radius_min/radius_max and count"},
      {"particles", "lattice", "", "(lattice) Simple, body-centred or face-centred cubic."},
      {"particles", "cell", "m", "(lattice) Cell size."},
      {"particles", "offset", "m", "(lattice) Offset of the first point from the corner."},
      {"particles", "corner", "m", "(lattice) Corner of the lattice."},
      {"particles", "counts", "", "(lattice) Cells along x, y, z (whole numbers, 1-10000); the scene holds at most 1e7 balls (about 15 GB)."},
      {"particles", "region_min", "m", "(random, agglomerates) Lower corner of the insertion box."},
      {"particles", "region_max", "m", "(random, agglomerates) Upper corner of the insertion box (agglomerates: whole bounding spheres inside)."},
      {"particles", "count", "", "(random) Number of bodies; or solid_fraction. (agglomerates) Number of agglomerates, required.", nullptr, "none: count or solid_fraction"},
      {"particles", "solid_fraction", "", "(random) Bodies to fill this fraction of the box volume (a size sweep fills the same space). Random insertion reaches about 0.27 with equal spheres, less with a size range or clumps: above 0.3 is refused. A scene holds at most 1e7 balls.", nullptr, "none: count or solid_fraction"},
      {"particles", "positions", "m", "(list) Body positions (clumps: centres of mass)."},
      {"particles", "radii", "m", "(list) One radius per position (spheres)."},
      {"particles", "velocities", "m/s", "(list) One velocity per position."},
      {"particles", "omegas", "rad/s", "(list) One angular velocity per position."},
      {"particles", "random_orientation", "", "(clumps) Random orientation of every clump not placed by random insertion."},
      {"particles", "member_radius", "m", "(four_ball) Radius of the four member spheres; or equivalent_diameter.", nullptr, "none: one of the two"},
      {"particles", "equivalent_diameter", "m", "(four_ball) Diameter of the sphere of equal Eq 4-2 volume; sets member_radius.", nullptr, "none: one of the two"},
      {"particles", "file", "", "(shape file) Clump file, one `x y z r` per line, relative to the scene."},
      {"particles", "scale", "", "(shape file) Factor on the clump file's coordinates and radii."},
      {"particles", "mass_distribution", "", "(clumps) How the mass is spread over the members for the inertia: the union at uniform density, equal member masses, or the plain sum of member spheres."},
      {"particles", "mass", "kg", "(clumps) Clump mass; 0 = density x the mass_volume."},
      {"particles", "mass_volume", "", "(clumps) Volume the mass is computed from: Eq 4-2 (four_ball only), the true union, or the sum of the members.", nullptr, "\"eq42\" (four_ball), \"union\" (file)"},
      {"particles", "principal_inertia", "kg m^2", "(shape file) Principal moments about the file's axes, with `mass` (rocklab shape's clump.toml)."},
      {"particles", "method", "", "(agglomerate) Hexagonal close packing, a dense random packing made at load time (§f.4, as `rocklab agglomerate --method dense`), or one agglomerate of a library made by `rocklab agglomerate`; (agglomerates) hcp or dense.", nullptr, "\"hcp\" (agglomerate), \"dense\" (agglomerates)"},
      {"particles", "diameter", "m", "(agglomerate hcp, dense) Diameter of the sphere the packing is cut to (dense: at least 4 r_max)."},
      {"particles", "r0", "", "(agglomerate dense, agglomerates dense) Size ratio r_max / r_min of Eq 5-11: the voids are filled down to radius/r0."},
      {"particles", "seed", "", "(agglomerate dense, agglomerates dense) The packing's own seed (scene.seed turns it when orientation = \"random\"; agglomerates: scene.seed draws their sizes, places and turns)."},
      {"particles", "pack", "", "(agglomerate dense, agglomerates dense) The loose pack: DEM servo compaction to 100 kPa, or the geometric stand-in."},
      {"particles", "hcp_angle", "deg", "(agglomerate hcp, agglomerates hcp) Rotation about z of the layers stacked along y."},
      {"particles", "gap_tolerance", "", "(agglomerate hcp, dense; agglomerates) Pairs closer than this fraction of the smaller radius are bonded."},
      {"particles", "library", "", "(agglomerate library) Library file (LIB.h5), relative to the scene."},
      {"particles", "index", "", "(agglomerate library) Which agglomerate of the library."},
      {"particles", "rotation", "deg", "(agglomerate) Rotation about x, then y, then z (world axes)."},
      {"particles", "orientation", "", "(agglomerate) \"random\" adds a seeded random rotation after `rotation`."},
      {"particles", "position", "m", "(agglomerate) Centre of the agglomerate."},
      {"particles", "diameter_min", "m", "(agglomerates) Smallest diameter; diameters uniform in [diameter_min, diameter_max].", nullptr, "required (agglomerates)"},
      {"particles", "diameter_max", "m", "(agglomerates) Largest diameter.", nullptr, "required (agglomerates)"},
      {"particles", "templates", "", "(agglomerates) Agglomerates made, one per equal class of diameter at its middle; each feed particle is its class's, scaled to its own diameter and turned at random."},

      // --- [bonds]
      {"bonds", "", "", "The parallel-bond model (Eq 2-27 to 2-38) and the strengths of the agglomerates' bonds."},
      {"bonds", "type", "", "Parallel bonds (§8.2), contact bonds (§8.1), or both on every bonded pair."},
      {"bonds", "contact_normal_strength", "N", "(contact) Tensile strength F_c^n of a contact bond, a force.", nullptr, "required (contact)"},
      {"bonds", "contact_shear_strength", "N", "(contact) Shear strength F_c^s of a contact bond, a force.", nullptr, "contact_normal_strength"},
      {"bonds", "radius_multiplier", "", "phi of Eq 2-35: bond radius = phi x the smaller ball radius."},
      {"bonds", "normal_stiffness", "Pa/m", "Normal stiffness per unit area (the study's \"N/m\" read as N/m^3)."},
      {"bonds", "shear_stiffness", "Pa/m", "Shear stiffness per unit area."},
      {"bonds", "failure_rule", "", "When a bond breaks: peak stress against strength (Eq 2-33, 2-34), or the sum of the four force and moment ratios."},
      {"bonds", "tensile_strength", "Pa", "Normal strength sigma_c (the 37 % value of the Weibull draws)."},
      {"bonds", "shear_strength", "Pa", "Shear strength tau_c.", nullptr, "tensile_strength"},
      {"bonds", "strength_distribution", "", "One strength for all bonds, a Weibull draw per bond, or one Weibull factor per agglomerate on both strengths."},
      {"bonds", "weibull_modulus", "", "Weibull modulus m of the draws (only with a Weibull distribution)."},

      // --- [[cameras]]
      {"cameras", "", "", "A pinhole camera with radial distortion (OpenCV's model) that renders frames at its own rate. Also the tables of a `rocklab render --camera` file."},
      {"cameras", "name", "", "Name; files are NAME.mp4, NAME_still_*.png, frames/NAME/, so a plain file name (no / or \\\\, not . or .., no control characters).", nullptr, "cameraINDEX"},
      {"cameras", "resolution", "px", "[width, height] in whole pixels.", "two whole numbers in [16, 8192]", "[640, 480]"},
      {"cameras", "fov_deg", "deg", "Horizontal field of view; or fx/fy/cx/cy.", nullptr, "none: fov_deg or fx"},
      {"cameras", "fx", "px", "Focal length along x (without fov_deg)."},
      {"cameras", "fy", "px", "Focal length along y.", nullptr, "fx"},
      {"cameras", "cx", "px", "Principal point x.", nullptr, "(width - 1) / 2"},
      {"cameras", "cy", "px", "Principal point y.", nullptr, "(height - 1) / 2"},
      {"cameras", "k1", "", "First radial distortion coefficient."},
      {"cameras", "k2", "", "Second radial distortion coefficient."},
      {"cameras", "frame_rate", "1/s", "Frames per second of simulated time."},
      {"cameras", "exposure", "s", "Exposure time (motion blur)."},
      {"cameras", "eye", "m", "Camera position."},
      {"cameras", "target", "m", "Point the camera looks at."},
      {"cameras", "up", "", "Up direction of the image."},
      {"cameras", "start_time", "s", "First frame."},
      {"cameras", "end_time", "s", "No frames after this time.", nullptr, "inf"},
      {"cameras", "movie", "", "Write NAME.mp4 (H.264; MJPG AVI as fallback)."},
      {"cameras", "movie_fps", "1/s", "Playback rate of the movie."},
      {"cameras", "still_interval", "s", "Simulated time between PNG stills; 0 = none."},
      {"cameras", "all_frames", "", "Write every frame as PNG to frames/NAME/ (what the tracker reads)."},
      {"cameras", "timestamp", "", "Time overlay on movie and stills."},
      {"cameras", "scale_bar", "", "Scale bar on movie and stills."},
      {"cameras", "colour_by", "", "Ball colours: by material, or by fragment (balls joined by intact bonds share a colour; the largest keeps the material's)."},
      {"cameras", "scale_depth", "m", "Depth along the view at which the scale bar is true.", nullptr, "distance eye-target"},
      {"cameras", "motion_blur", "", "Average sub-frames over the exposure (needs exposure > 0)."},
      {"cameras", "noise_sigma", "", "Gaussian image noise, in grey levels."},
      {"cameras", "light_gain", "", "Brightness factor."},
      {"cameras", "ambient", "", "Light from all sides, as a fraction of a material's colour (a sizing station's dome light: high ambient, low diffuse)."},
      {"cameras", "diffuse", "", "The lamp at the camera: diffuse fraction of a material's colour (a sphere darkens towards its outline)."},
      {"cameras", "specular", "", "The lamp's white highlight (Blinn-Phong)."},
      {"cameras.cut", "", "", "A cut-away: what lies beyond a plane is not drawn, so the inside of a closed chamber shows. Walls are clipped per pixel (their cut edges and inner faces show); a ball is dropped whole when its centre lies beyond the plane. An empty table cuts along the vertical plane through target that faces the camera. With wedge_normal only what lies beyond both planes goes: a quarter cut-away (docs/camera.md)."},
      {"cameras.cut", "point", "m", "A point on the cut plane.", nullptr, "target"},
      {"cameras.cut", "normal", "", "Normal of the plane, pointing into the half that is removed (any length).", nullptr, "from point towards eye, its part along up removed (the half nearest the camera goes)"},
      {"cameras.cut", "wedge_normal", "", "Normal of a second plane through point, pointing into its removed half (any length, not parallel to normal): only what lies beyond both planes is removed, a wedge; perpendicular normals remove a quarter, which shows two sections and the surfaces between them.", nullptr, "none (the first plane alone)"},

      // --- [experiment]
      {"experiment", "", "", "The experiment type and the keys every type has; the other keys depend on the type (tables below)."},
      {"experiment", "type", "", "The driver: drop, heap, chute (also the zoned chute), zwick, crusher or product_photo."},
      {"experiment", "sample_interval", "s", "Time between the driver's samples (the lab filmed at 500 frames/s)."},
      {"experiment", "check_interval", "", "Renamed: use sample_interval (s); a scene that still has it is refused with that message.", "none", "none"},
      {"experiment.drop", "", "", "type = \"drop\": one body dropped on a wall; restitution from the normal velocity before and after the impact. No keys of its own."},
      {"experiment.heap", "", "", "type = \"heap\": bodies poured from a lifted tube (a wall with motion) settle into a heap; angle of repose."},
      {"experiment.heap", "settle_speed", "m/s", "Settled when no body is faster."},
      {"experiment.heap", "settle_min_time", "s", "Not settled before this time."},
      {"experiment.heap", "settle_max_time", "s", "Give up settling at this time (reported, not hidden)."},
      {"experiment.heap", "calibration_photos", "", "Checkerboard photos the side camera is calibrated from (3-11); 0 = the renderer's exact camera."},
      {"experiment.heap", "base_z", "m", "Height of the table."},
      {"experiment.heap", "bin_width", "m", "Silhouette bin width of the angle measurement."},
      {"experiment.chute", "", "", "type = \"chute\": deposit, markers, tilt, gate opening, discharge. Frame: outlet at x = 0, base z = 0, camera wall y = 0."},
      {"experiment.chute", "settle_speed", "m/s", "The deposit is settled when no body is faster."},
      {"experiment.chute", "settle_min_time", "s", "Not settled before this time."},
      {"experiment.chute", "settle_max_time", "s", "Give up settling at this time (reported)."},
      {"experiment.chute", "calibration_photos", "", "Checkerboard photos the tracking camera is calibrated from (3-11); 0 = the renderer's exact camera."},
      {"experiment.chute", "length", "m", "Length of the chute from the outlet to the feed end."},
      {"experiment.chute", "inclination_deg", "deg", "Test inclination of the base."},
      {"experiment.chute", "deposit_inclination_deg", "deg", "Inclination while depositing (zoned chute: 45)."},
      {"experiment.chute", "gravity_tilt", "", "How the tilt enters: gravity rotated (its magnitude kept), or the study's added component g tan(angle) along the base."},
      {"experiment.chute", "gate_wall", "", "Wall removed to release the flow.", "a wall name"},
      {"experiment.chute", "top_wall", "", "Wall added after deposition (the zoned chute's top plate); bodies it cuts are removed.", "a wall name", "none"},
      {"experiment.chute", "settle_scope", "", "Whose speed ends the deposit with a top_wall: the balls the plate keeps (those it cuts are deleted, so their rolling does not hold the deposit) or every ball.", "\"kept\", \"all\"", "\"kept\""},
      {"experiment.chute", "stop_after", "", "\"deposit\": the run ends where the deposit is over, before the top plate is placed (needs output.checkpoint = true), so that one deposit serves every plate of a study: rocklab restart CHECKPOINT --set walls.top..., or rocklab sweep CHECKPOINT --vary walls.top...; a restart goes on to the test. \"none\": the whole test.", "\"none\", \"deposit\"", "\"none\""},
      {"experiment.chute", "temporary_walls", "", "Walls removed after deposition (zone separators).", "wall names"},
      {"experiment.chute", "tilt_steps", "", "Steps at the test inclination with the gate closed."},
      {"experiment.chute", "marker_columns", "m", "Distances of the marker columns from the outlet, column 1 first."},
      {"experiment.chute", "marker_heights", "m", "Marker heights above the base, the same in every column; or marker_height_fractions."},
      {"experiment.chute", "marker_height_fractions", "", "Marker heights as fractions of the local channel height (top plate, else bed)."},
      {"experiment.chute", "marker_y", "m", "Distance of the marker centres from the camera wall; 0 = one radius."},
      {"experiment.chute", "measure_distance", "m", "Travel over which a marker's mean velocity is taken."},
      {"experiment.chute", "remove_beyond", "m", "Bodies this far past the outlet are deleted."},
      {"experiment.chute", "jam_time", "s", "No discharge for this long while bodies remain = jammed; the run stops."},
      {"experiment.chute", "track", "", "Track the markers in the frames of track_camera."},
      {"experiment.chute", "track_camera", "", "Camera whose frames are tracked.", "a camera name", "the first camera"},
      {"experiment.chute", "track_position", "", "A marker's position: \"shape\" fits the projected outline of its clump (touching the camera wall, so the depth follows from the fitted orientation) to the blob's sub-pixel edges, seeded from the track's previous pose; \"centroid\" is the blob's redness-weighted centroid on the plane of the marker centres (docs/camera.md)."},
      {"experiment.product_photo", "", "", "type = \"product_photo\": particles settle on a tray; the first camera photographs them from above and their sizes are measured from the photograph (docs/crusher.md, product size from images) against the settled balls' true diameters."},
      {"experiment.product_photo", "settle_speed", "m/s", "At rest when no body is faster; the photograph is the camera's last frame before."},
      {"experiment.product_photo", "settle_min_time", "s", "Not at rest before this time."},
      {"experiment.product_photo", "settle_max_time", "s", "Give up waiting at this time (reported, not hidden)."},
      {"experiment.product_photo", "surface_z", "m", "Height of the tray the particles lie on (its normal is +z)."},
      {"experiment.product_photo", "sieves_mm", "mm", "Sieve sizes of the cumulative passing, increasing."},
      {"experiment.product_photo", "threshold", "", "Grey level (0-255) above which a pixel is a particle; below 0: Otsu's threshold of the photograph."},
      {"experiment.product_photo", "outline_iterations", "", "Updates of the plane a particle is sized on (half its size above the tray); 0 sizes it on the tray plane."},
      {"experiment.crusher", "", "", "type = \"crusher\": the cone crusher's run (docs/crusher.md): spheres below discharge_height are product (removed, size and mass in product.csv); ends when the chamber is empty."},
      {"experiment.crusher", "discharge_height", "m", "Height below which a ball's centre is discharged product (below the concave's bottom lip); a bonded feed's fragment: its centre of mass."},
      {"experiment.crusher", "settle_bond_factor", "", "(bonded feed, §g.7) The bonds' strengths times this until the feed bin's stop wall goes (crusher.release_time), so the feed settles unbroken; 1 = off."},
      {"experiment.crusher", "sieves_mm", "mm", "Sieve sizes of the product's cumulative passing, increasing."},
      {"experiment.crusher", "whiten_k1_mm", "mm", "k1 of Whiten's classification (Eq 3-21 to 3-23), below which nothing is selected for breakage; 0: the built chamber's closed-side gap."},
      {"experiment.crusher", "whiten_k2_mm", "mm", "k2 of Whiten's classification, above which everything is selected; 0: the built chamber's open-side setting."},
      {"experiment.crusher", "whiten_exponent", "", "Exponent of Eq 3-22 (the study prints 2; Whiten's fits are often about 2.3)."},
      {"experiment.crusher.breakage", "", "", "[experiment.breakage] of type = \"crusher\": population-balance breakage (experiments.md §g.6, docs/crusher.md); off without the table. A ball of at least min_diameter whose octahedral shear stress exceeds its strength is replaced by fragments, which a freeze eases apart."},
      {"experiment.crusher.breakage", "check_interval", "s", "Time between breakage checks; 0 = automatic: a quarter of the contact time pi sqrt(m/k) of a ball of min_diameter on a wall, so every impact is seen near its peak (results.json: crusher.breakage.check_interval_s)."},
      {"experiment.crusher.breakage", "start", "", "When the checks begin (§g.4 [X]): \"feed\" from t = 0, so the feed may break in the feed bin; \"release\" when the stop wall goes (crusher.release_time; t = 0 without a feed bin), so only the chamber breaks balls (results.json: crusher.breakage.start, checks_from_s).", "\"feed\", \"release\"", "\"feed\""},
      {"experiment.crusher.breakage", "q_ref", "Pa", "q0 at d_ref: the octahedral shear strength 37 % of the balls of that size exceed (Weibull scale)."},
      {"experiment.crusher.breakage", "d_ref", "m", "Size q_ref belongs to ([I]: 21 mm, the middle of the 14-28 mm feed)."},
      {"experiment.crusher.breakage", "size_exponent", "", "b of the size effect q0(d) = q_ref (d / d_ref)^b (Eq 6-13)."},
      {"experiment.crusher.breakage", "weibull_modulus", "", "m: a ball's strength is q0(d) (-ln U)^(1/m), U drawn from scene.seed and the ball's id."},
      {"experiment.crusher.breakage", "min_diameter", "m", "Balls smaller than this never break (Table 6.2: 4 mm); also sets the smallest fragment the step must hold."},
      {"experiment.crusher.breakage", "mode", "", "Fragments: three of 60/30/10 % of the mass, or two halves.", "\"triple\", \"equal\""},
      {"experiment.crusher.breakage", "offsets", "", "Fragment centres along the minor principal stress direction, in parent radii, one per fragment, each fragment inside the parent. Default: triple [-0.157, 0.331, 0] (60 % and 30 % internally tangent at opposite ends, 10 % at the centre), equal [-0.206, 0.206]."},
      {"experiment.crusher.breakage", "youngs_modulus", "Pa", "E_c of the fragments' stiffness k = 4 R E_c (Eq 6-14), R the middle of the fragment's size class."},
      {"experiment.crusher.breakage", "class_ratio", "", "Width of the fragments' size classes (diameters min_diameter x ratio^i to ^(i+1)); each class is a material with its own k."},
      {"experiment.crusher.breakage", "freeze_scope", "", "Who takes part in the freeze: \"local\" the fragments and the balls within freeze_local_reach of them, those that bear load held still and the loose ones moving like fragments (the freeze's step is the fragments' own, a few dozen balls); \"all\" every ball of the run at freeze_density (§g.6 step 3 as written; the step is set by the unbroken balls' rock stiffness).", "\"local\", \"all\""},
      {"experiment.crusher.breakage", "freeze_density", "kg/m^3", "Density during the freeze (§g.6 step 3): every ball's (scope \"all\") or the fragments' (\"local\")."},
      {"experiment.crusher.breakage", "freeze_held_density", "kg/m^3", "Scope \"local\": the density of the held neighbours, so huge that the fragments cannot move them."},
      {"experiment.crusher.breakage", "freeze_local_reach", "", "Scope \"local\": the neighbours taken in, within this many largest-fragment diameters of a fragment (surface to surface); a fragment that ends touching a ball beyond it doubles the reach and the freeze runs again."},
      {"experiment.crusher.breakage", "freeze_stiffness", "N/m", "The fragments' kn and ks during the freeze (§g.6 step 4)."},
      {"experiment.crusher.breakage", "freeze_local_damping", "", "Local damping alpha during the freeze (§g.6 step 5; viscous damping off)."},
      {"experiment.crusher.breakage", "freeze_overlap_fraction", "", "The freeze may end when no fragment overlaps a ball by more than this fraction of the smaller radius, nor a wall by more than this fraction of its own."},
      {"experiment.crusher.breakage", "freeze_kinetic_fraction", "", "...and the kinetic energy is below this fraction of the energy the fragments' overlaps stored at the freeze stiffness."},
      {"experiment.crusher.breakage", "freeze_stall_tolerance", "", "The freeze also ends (\"stalled\") when the kinetic criterion holds and the largest fragment overlap has not fallen below (1 - this) of its value freeze_stall_window ago: fragments pinched between the held walls or heavy neighbours, whose overlap cannot reach freeze_overlap_fraction."},
      {"experiment.crusher.breakage", "freeze_stall_window", "", "The window of the stall rule in the heaviest fragment's time scale sqrt(m/k) at the freeze density and stiffness (not in cycles: the freeze's step is set by the unbroken balls); 0 = no stall rule (only the overlap criterion ends a freeze)."},
      {"experiment.crusher.breakage", "freeze_stall_max_overlap", "", "The stall rule ends a freeze only when the largest fragment overlap (with a ball or a wall) is at most this fraction of the smaller radius: handed back at rock stiffness k = 4 R E_c an overlap f R loads a ball to q = 0.9 E_c f (19 MPa at the default 3e-4, below the feed's strengths); higher plateaus are squeezes the fragments leave later, or crowded freezes."},
      {"experiment.crusher.breakage", "freeze_max_contact_times", "", "A freeze that has not ended either way after this many contact times pi sqrt(m/k) of its heaviest mover (fragments and loose neighbours, at freeze_density and freeze_stiffness) is crowded: its fragments found no room (freeze_crowded says what follows). Free fragments part in about 1.6 (5 sqrt(m/k) under local damping 0.9), the slowest freeze seen to part took 5-10; 0 = freeze_max_cycles only."},
      {"experiment.crusher.breakage", "freeze_jam_contact_times", "", "A freeze at rest whose largest overlap (above freeze_stall_max_overlap) has not fallen by freeze_stall_tolerance over the last this many contact times of its heaviest mover is crowded before freeze_max_contact_times: its fragments are jammed among held neighbours (docs/crusher.md, the freeze's cost). Must be longer than the slowest escape seen (5-10); 0 = off."},
      {"experiment.crusher.breakage", "freeze_max_cycles", "", "...and never more cycles than this (the cap in cycles of the freeze's own step; with freeze_scope \"all\" the rock balls set that step, and this is the cap that binds)."},
      {"experiment.crusher.breakage", "freeze_crowded", "", "After a crowded freeze: \"break\" keeps the breakage with the fragments where the freeze left them (freeze_end \"crowded\" in breakage.csv) while it is within freeze_crowded_bound, otherwise the parents wait as with \"defer\"; \"defer\" keeps the parents whole for defer_time (results.json breakage.deferred); \"stop\" stops the run with the criteria's values.", "\"break\", \"defer\", \"stop\""},
      {"experiment.crusher.breakage", "freeze_crowded_bound", "", "freeze_crowded = \"break\": what bounds a crowded breakage that is kept. \"energy\": the elastic energy the contacts of the balls the freeze moved hold afterwards, at the run's contact law and stiffness (fragment-ball and fragment-wall), is at most freeze_crowded_energy_factor times what the parents' contacts stored at the check that broke them (no energy created; breakage.csv parent_energy_J, handed_back_energy_J). \"overlap\": the largest overlap is at most freeze_crowded_max_overlap (docs/crusher.md, eighth attempt).", "\"energy\", \"overlap\""},
      {"experiment.crusher.breakage", "freeze_crowded_energy_factor", "", "freeze_crowded_bound = \"energy\": the elastic energy a kept crowded breakage may hand back, as a multiple of what its parents' contacts stored (1: none created)."},
      {"experiment.crusher.breakage", "freeze_crowded_max_overlap", "", "freeze_crowded = \"break\", freeze_crowded_bound = \"overlap\": the largest fragment overlap (fraction of the smaller radius, of its own with a wall) a crowded freeze may hand back; an overlap f R at rock stiffness k = 4 R E_c loads a ball to q = 0.9 E_c f (19 MPa at the default 3e-4, as freeze_stall_max_overlap)."},
      {"experiment.crusher.breakage", "freeze_defer_crowded", "", "Replaced by freeze_crowded (true is \"defer\", false \"stop\"); a scene that still has it is refused with that message.", "none", "none"},
      {"experiment.crusher.breakage", "defer_time", "s", "How long a ball whose fragments found no room stays whole before it may break again; 0 = until the next check. The closing mantle loads a whole ball while it waits: where the PBM chamber closes fastest, by about its own strength in 17-22 us (docs/crusher.md)."},
      {"experiment.crusher.breakage", "freeze_check_cycles", "", "Cycles between looks at the freeze's end criterion (at most a quarter of the stall window)."},
      {"experiment.zwick", "", "", "type = \"zwick\": an agglomerate crushed between two plane platens; failure load and strength."},
      {"experiment.zwick", "bottom_platen", "", "Plane wall the specimen rests on.", "a plane wall name"},
      {"experiment.zwick", "top_platen", "", "Plane wall that closes on the specimen.", "a plane wall name"},
      {"experiment.zwick", "platen_speed", "m/s", "Closing speed of the top platen (Table 5.2: 0.008)."},
      {"experiment.zwick", "settle_first", "", "Let the specimen settle on the bottom platen under gravity before loading."},
      {"experiment.zwick", "settle_speed", "m/s", "(settle_first) Settled when no ball is faster."},
      {"experiment.zwick", "settle_min_time", "s", "(settle_first) Not settled before this time."},
      {"experiment.zwick", "settle_max_time", "s", "(settle_first) Give up settling at this time."},
      {"experiment.zwick", "start_gap", "m", "Gap between the top platen and the specimen when loading starts."},
      {"experiment.zwick", "sample_travel", "m", "Platen travel between samples while loading (0: every sample_interval)."},
      {"experiment.zwick", "max_strain", "", "Loading ends when the platens have closed by this fraction of the specimen size."},
      {"experiment.zwick", "failure_volume_fraction", "", "Failed once the pieces broken off the largest fragment exceed this fraction of the volume.", nullptr, "1/3"},
      {"experiment.zwick", "end_drop", "", "After failure the test ends when the load has fallen below (1 - end_drop) x peak."},
      {"experiment.zwick", "fines_size", "m", "Fragments of smaller equivalent diameter are fines (the lab's 8 mm sieve)."},

      // --- [output]
      {"output", "", "", "What the run writes into its output folder."},
      {"output", "frame_interval", "s", "Time between trajectory frames in run.h5; 0 = first and last only."},
      {"output", "energy_interval", "s", "Time between energy-log rows; 0 = at frames only."},
      {"output", "checkpoint_interval", "s", "Time between checkpoints; 0 = at the end only."},
      {"output", "hdf5", "", "Write run.h5."},
      {"output", "vtk", "", "Write a ParaView series vtk/particles_*.vtp and particles.pvd, and (mesh or polygon walls) vtk/walls_*.vtp and walls.pvd at the walls' poses."},
      {"output", "checkpoint", "", "Write checkpoint.h5 (rocklab restart)."},
  };
  return docs;
}

std::string sceneKeyUnit(const std::string& path) {
  // The path's parts; the key is the last part that is not an index.
  std::vector<std::string> parts;
  std::stringstream in(path);
  for (std::string part; std::getline(in, part, '.');) parts.push_back(part);
  while (!parts.empty() && !parts.back().empty() &&
         parts.back().find_first_not_of("0123456789") == std::string::npos)
    parts.pop_back();
  if (parts.size() < 2) return "";
  const std::string& key = parts.back();
  std::string unit;
  bool found = false;
  for (const KeyDoc& d : sceneKeyDocs()) {
    const std::string table = d.table;
    if (key != d.key || table.substr(0, table.find('.')) != parts.front()) continue;
    if (found && unit != d.unit) return "";  // the tables that have the name disagree
    unit = d.unit;
    found = true;
  }
  return unit;
}

std::string withSceneKeyUnit(const std::string& path) {
  const std::string unit = sceneKeyUnit(path);
  return unit.empty() ? path : path + " (" + unit + ")";
}

namespace {

/// Scenes that reach the reader branches the built-in scenes do not (every wall
/// type, particle source and shape, the camera intrinsics, bond strengths).
/// Paths are relative to the built-in scene folder; LIBRARY is replaced by a
/// library file written for the purpose.
const char* const kCoverageScenes[] = {
    R"(
[scene]
name = "coverage-engine"
steps = 1
[materials.a]
colour = [0.5, 0.5, 0.5]
kn = 1e6
ks = 1e6
friction = 0.5
shear_modulus = 1e9
poisson = 0.25
density = 2600
[contact]
law = "linear"
damping_normal = 0.1
damping_shear = 0.1
damping_mass = "reduced"
friction_rule = "min"
local_damping = 0.0
stiffness_scale = 1.0
[gravity]
vector = [0, 0, -9.81]
[[gravity.change]]
time = 1.0
vector = [0, 0, -1]
[timestep]
safety_factor = 0.3
dt = 0
impact_velocity = 2
allow_unsafe = false
[neighbours]
skin = 0.001
max_levels = 4
[watchdog]
max_overlap_fraction = 0.5
max_energy_growth = 0.1
check_interval = 100
network_iterations = 2
network_interval = 1000
[relaxation]
steps = 0
[[walls]]
type = "plane"
name = "floor"
material = "a"
point = [0, 0, 0]
normal = [0, 0, 1]
active_from = 0
active_until = 10
colour = [0.2, 0.2, 0.2]
opacity = 1
visible = true
plane_size = 1
[walls.motion]
velocity = [0, 0, 0]
pivot = [0, 0, 0]
amplitude = [0, 0, 0.001]
frequency = 10
[[walls]]
type = "polygon"
material = "a"
vertices = [[0, 0, 1], [1, 0, 1], [1, 1, 1]]
[[walls]]
type = "plate"
material = "a"
corner = [0, 0, 2]
length = 1
width = 1
angle_deg = 10
[[walls]]
type = "mesh"
material = "a"
file = "../meshes/pebble-1.stl"
scale = 0.001
[[walls]]
type = "mesh"
material = "a"
vertices = [[0, 0, 3], [1, 0, 3], [0, 1, 3]]
triangles = [[0, 1, 2]]
[[walls]]
type = "box"
material = "a"
min = [-1, -1, -1]
max = [-0.5, -0.5, -0.5]
open_top = false
[[particles]]
type = "lattice"
material = "a"
radius = 0.01
lattice = "fcc"
cell = 0.05
offset = [0, 0, 0]
corner = [5, 5, 5]
counts = [2, 2, 2]
velocity = [0, 0, 0]
[[particles]]
type = "random"
material = "a"
radius_min = 0.01
radius_max = 0.012
region_min = [5, 5, 6]
region_max = [5.2, 5.2, 6.2]
solid_fraction = 0.1
[[particles]]
type = "random"
material = "a"
radius = 0.01
region_min = [5, 5, 7]
region_max = [5.2, 5.2, 7.2]
count = 3
[[particles]]
type = "list"
material = "a"
positions = [[6, 6, 6], [6.1, 6, 6]]
radii = [0.01, 0.01]
velocities = [[0, 0, 0], [0, 0, 0]]
omegas = [[0, 0, 0], [0, 0, 0]]
[[particles]]
type = "list"
material = "a"
shape = "four_ball"
member_radius = 0.005
mass_distribution = "equal_mass"
mass = 0.01
random_orientation = false
positions = [[7, 7, 7]]
[[particles]]
type = "list"
material = "a"
shape = "four_ball"
equivalent_diameter = 0.02
mass_volume = "union"
positions = [[7.2, 7, 7]]
[[particles]]
type = "list"
material = "a"
shape = "file"
file = "../clumps/pebble-1.txt"
scale = 1.0
mass = 0.01
principal_inertia = [1e-7, 1.2e-7, 1.4e-7]
positions = [[8, 8, 8]]
[[cameras]]
name = "pinhole"
resolution = [320, 240]
fx = 300
fy = 300
cx = 160
cy = 120
k1 = 0.01
k2 = 0
frame_rate = 100
exposure = 0.001
eye = [0, -1, 0.5]
target = [0, 0, 0]
up = [0, 0, 1]
start_time = 0
end_time = 1
movie = false
movie_fps = 25
still_interval = 0
all_frames = false
timestamp = false
scale_bar = false
scale_depth = 1
motion_blur = true
noise_sigma = 1
light_gain = 1
ambient = 0.35
diffuse = 0.65
specular = 0.2
[cameras.cut]
point = [0, 0, 0]
normal = [-1, 0, 0]
wedge_normal = [0, -1, 0]
[output]
frame_interval = 0
energy_interval = 0
checkpoint_interval = 0
hdf5 = false
vtk = false
checkpoint = false
)",
    R"(
[scene]
name = "coverage-bonds"
end_time = 0.1
[materials.rock]
shear_modulus = 1e9
[contact]
law = "hertz_mindlin"
[bonds]
type = "parallel+contact"
contact_normal_strength = 10
contact_shear_strength = 5
radius_multiplier = 1
normal_stiffness = 1e12
shear_stiffness = 1e12
failure_rule = "combined"
tensile_strength = 1e7
shear_strength = 1e7
strength_distribution = "weibull_per_bond"
weibull_modulus = 3
[[particles]]
type = "agglomerate"
material = "rock"
method = "hcp"
radius = 0.0025
diameter = 0.012
hcp_angle = 10
gap_tolerance = 1e-3
rotation = [0, 0, 0]
orientation = "random"
position = [0, 0, 0]
velocity = [0, 0, 0]
[[particles]]
type = "agglomerate"
material = "rock"
method = "library"
library = "LIBRARY"
index = 0
position = [1, 0, 0]
)",
    R"(
[scene]
name = "coverage-crusher-breakage"
steps = 1
[materials.rock]
[[particles]]
type = "list"
material = "rock"
radius = 0.01
positions = [[0, 0, 0]]
[experiment]
type = "crusher"
[experiment.breakage]
check_interval = 0.001
q_ref = 25.2e6
d_ref = 0.021
size_exponent = -1.1
weibull_modulus = 2.65
min_diameter = 0.004
mode = "triple"
offsets = [-0.15, 0.33, 0]
youngs_modulus = 70e9
class_ratio = 1.25
freeze_scope = "local"
freeze_density = 3e9
freeze_held_density = 1e30
freeze_local_reach = 1.0
freeze_stiffness = 1e3
freeze_local_damping = 0.9
freeze_overlap_fraction = 1e-4
freeze_kinetic_fraction = 0.2
freeze_stall_tolerance = 0.01
freeze_stall_window = 2
freeze_stall_max_overlap = 3e-4
freeze_max_contact_times = 100
freeze_jam_contact_times = 0
freeze_max_cycles = 1000000
freeze_check_cycles = 20
freeze_crowded = "break"
freeze_crowded_max_overlap = 3e-4
freeze_crowded_bound = "energy"
freeze_crowded_energy_factor = 1
defer_time = 2e-5
)",
};

/// A library of one agglomerate (two bonded spheres) for the coverage scene.
std::filesystem::path writeCoverageLibrary() {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("rocklab-scene-keys-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  AgglomerateRecord a;
  a.method = "hcp";
  a.r_max = 0.001;
  a.r0 = 1;
  a.diameter = 0.004;
  a.spheres = {{geometry::Vec3(-0.001, 0, 0), 0.001}, {geometry::Vec3(0.001, 0, 0), 0.001}};
  a.bonds = {{0, 1}};
  a.sphere_count = 2;
  a.bond_count = 1;
  writeAgglomerateLibrary(dir / "lib.h5", {a});
  return dir;
}

std::string cell(const std::string& s) { return s.empty() ? " " : s; }

/// "a", "a or b" of the distinct non-empty strings of `values`, in order.
std::string joined(const std::vector<std::string>& values, const std::string& sep) {
  std::vector<std::string> seen;
  for (const auto& v : values)
    if (!v.empty() && std::find(seen.begin(), seen.end(), v) == seen.end()) seen.push_back(v);
  return detail::joinedText(seen, sep);
}

std::string heading(const std::string& table) {
  if (table == "walls" || table == "particles" || table == "cameras" || table == "gravity.change")
    return "[[" + table + "]]";
  if (table.rfind("experiment.", 0) == 0) {
    // A driver's sub-table ("experiment.crusher.breakage"): [experiment.breakage] of that type.
    const std::string type = table.substr(11), sub = type.substr(0, type.find('.'));
    if (sub != type) return "[experiment." + type.substr(sub.size() + 1) + "] of type = \"" + sub + "\"";
    return "[experiment] type = \"" + type + "\"";
  }
  return "[" + table + "]";
}

}  // namespace

std::string sceneKeysMarkdown(std::vector<std::string>& problems) {
  // 1. Read the corpus with recording on.
  detail::recordSceneKeys(true);
  std::vector<std::filesystem::path> builtins;
  for (const auto& e : std::filesystem::directory_iterator(builtinSceneDir()))
    if (e.path().extension() == ".toml") builtins.push_back(e.path());
  std::sort(builtins.begin(), builtins.end());
  for (const auto& f : builtins) {
    try {
      loadScene(f);
    } catch (const std::exception& e) {
      problems.push_back(f.filename().string() + ": " + e.what());
    }
  }
  const std::filesystem::path library_dir = writeCoverageLibrary();
  for (std::string text : kCoverageScenes) {
    if (const auto at = text.find("LIBRARY"); at != std::string::npos)
      text.replace(at, 7, (library_dir / "lib.h5").string());
    try {
      loadSceneText(text, "coverage scene", {}, builtinSceneDir());
    } catch (const std::exception& e) {
      problems.push_back(std::string("coverage scene: ") + e.what());
    }
  }
  std::filesystem::remove_all(library_dir);
  const std::vector<detail::KeyRead> reads = detail::recordedSceneKeys();
  detail::recordSceneKeys(false);

  // 2. Join the reads with the documentation lines.
  std::map<std::pair<std::string, std::string>, std::vector<const detail::KeyRead*>> read_by_key;
  for (const auto& r : reads) read_by_key[{r.table, r.key}].push_back(&r);
  std::set<std::pair<std::string, std::string>> documented;
  for (const KeyDoc& d : sceneKeyDocs()) {
    if (!documented.insert({d.table, d.key}).second)
      problems.push_back(std::string("documented twice: ") + d.table + " " + d.key);
  }
  for (const auto& [id, rs] : read_by_key) {
    const bool is_table = rs.front()->kind == "table" || rs.front()->kind == "array of tables";
    const std::string name = (id.first.empty() ? "" : id.first + ".") + id.second;
    if (!is_table && !documented.count(id))
      problems.push_back("undocumented scene key '" + name +
                         "': add its line to sceneKeyDocs() in experiments/src/scene/scene_keys.cpp");
    if (is_table && !documented.count({name, ""}))
      problems.push_back("undocumented table [" + name + "]: add its line {\"" + name +
                         "\", \"\", ...} to sceneKeyDocs()");
  }

  std::ostringstream md;
  md << "# Scene file reference\n\n"
        "<!-- Generated by `rocklab scene-keys` from the scene readers; do not edit.\n"
        "     Regenerate: build/app/rocklab scene-keys > docs/scene-format.md -->\n\n"
        "Every table and key a scene file may hold, as the readers read it: the type, the\n"
        "unit (SI), the values allowed, the default and what it does. It is generated by\n"
        "`rocklab scene-keys`, which loads every built-in scene and a few coverage scenes\n"
        "with the readers recording each key they ask for, and joins those records with\n"
        "one line of documentation per key (`experiments/src/scene/scene_keys.cpp`). The\n"
        "test `scene-keys` fails when a reader reads a key without a line there, when a\n"
        "line names a key no reader reads, or when this file differs from the command's\n"
        "output.\n\n"
        "General rules:\n\n"
        "- A scene is a TOML file. Units are SI (m, s, kg, N, Pa; angles in degrees where the\n"
        "  key says `_deg`).\n"
        "- `extends = \"other.toml\"` at the top takes every key of that scene (path relative\n"
        "  to this file) and lays this file's keys over it: tables merge key by key, anything\n"
        "  else (values, arrays, arrays of tables such as `[[walls]]`) replaces the base's.\n"
        "- `remove = [\"walls.zone_wall_1\", ...]` at the top drops entries of an array of\n"
        "  tables, each found by its `name` (ARRAY.NAME), after `extends` has merged: an\n"
        "  extending scene leaves out an inherited wall without repeating the list. A name\n"
        "  that matches no entry is an error that lists the names there are.\n"
        "- Every key is checked when the scene is loaded: an unknown key, a wrong type, a\n"
        "  value out of range or a missing file stops with one message naming the file, line,\n"
        "  key, value and what is allowed (exit code 2), before anything is written.\n"
        "- `--set key.path=value` (run, check, sweep, study) overrides any key with a TOML\n"
        "  value; `particles.0.count=200` indexes an array of tables, `walls.gate.active_until=0.3`\n"
        "  finds an entry by its `name`.\n"
        "- \"required\" means the key has no default; keys marked (plane), (lattice), ... are\n"
        "  read only for that type or shape.\n\n";

  // The top-level tables as a list, then one section per table.
  std::string current;
  for (const KeyDoc& d : sceneKeyDocs()) {
    const std::string table = d.table;
    const std::string key = d.key;
    if (table.empty()) continue;
    if (key.empty()) {
      if (!current.empty()) md << "\n";
      current = table;
      md << "## " << heading(table) << "\n\n" << d.text << "\n\n";
      // A table without keys of its own (experiment.drop) gets no key table.
      bool has_keys = false;
      for (const KeyDoc& k : sceneKeyDocs())
        if (table == k.table && *k.key) has_keys = true;
      if (has_keys)
        md << "| key | type | unit | allowed | default | meaning |\n|---|---|---|---|---|---|\n";
      continue;
    }
    if (table != current) {
      problems.push_back("documentation line of " + table + "." + key +
                         " is not in its table's group (after the line with key \"\")");
      continue;
    }
    const auto found = read_by_key.find({table, key});
    if (found == read_by_key.end()) {
      problems.push_back("documented key '" + table + "." + key +
                         "' is read by no scene of the corpus: removed from the reader, or a branch the "
                         "coverage scenes of scene_keys.cpp do not reach");
      continue;
    }
    std::vector<std::string> kinds, allowed, defaults;
    for (const detail::KeyRead* r : found->second) {
      if (r->kind.empty()) continue;  // has(): only asked about
      kinds.push_back(r->kind);
      if (r->kind == "table" || r->kind == "array of tables") continue;
      allowed.push_back(r->allowed == "any number" ? "" : r->allowed);
      defaults.push_back(r->required ? "required" : r->fallback);
    }
    // A key only asked about with has() (a renamed key that is refused with its new
    // name) is documented by its `values` line; any other must be read somewhere.
    if (kinds.empty() && !d.values) {
      problems.push_back("key '" + table + "." + key +
                         "' is only asked about (has()) in the corpus: read it in a coverage scene");
      continue;
    }
    const std::string kind = kinds.empty() ? std::string("(refused)") : joined(kinds, " or ");
    std::string values = d.values ? d.values : joined(allowed, "; ");
    if (values == "true, false") values.clear();
    const std::string fallback_list = joined(defaults, " / ");
    if (!d.fallback && fallback_list.find(" / ") != std::string::npos)
      problems.push_back("key '" + table + "." + key + "' has different defaults in different scenes (" +
                         fallback_list + "): give its default text in scene_keys.cpp");
    // The reader's own default as TOML text; a documentation line's default, or
    // "required", as words.
    const bool is_table = kind == "table" || kind == "array of tables";
    std::string fallback = d.fallback ? d.fallback : fallback_list;
    if (!d.fallback && fallback != "required" && !fallback.empty()) fallback = "`" + fallback + "`";
    md << "| `" << key << "` | " << kind << " | " << cell(d.unit) << " | " << cell(values) << " | "
       << cell(is_table ? std::string() : fallback) << " | " << d.text << " |\n";
  }
  // Top-level keys: the table list.
  std::ostringstream top;
  top << "## Top level\n\n| table | meaning |\n|---|---|\n";
  for (const KeyDoc& d : sceneKeyDocs())
    if (!*d.table) {
      if (!read_by_key.count({"", d.key}))
        problems.push_back(std::string("documented table '") + d.key + "' is read by no scene of the corpus");
      top << "| " << heading(d.key) << " | " << std::string(d.text).substr(std::string(d.text).find(':') + 2)
          << " |\n";
    }
  std::string out = md.str();
  const auto first_section = out.find("\n## ");
  out.insert(first_section + 1, top.str() + "\n");
  return out;
}

}  // namespace rocklab::experiments
