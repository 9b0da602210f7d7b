#include "grainlink/dem/Scenario.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace grainlink::dem {

namespace {

Vec3 gravityOf(const ConfigNode &node) {
    if (node.isSequence())
        return node.vec3();
    const std::string body = node.choice({"earth", "mars", "moon", "none"});
    if (body == "earth")
        return Vec3(0, 0, -9.81);
    if (body == "mars")
        return Vec3(0, 0, -3.71);
    if (body == "moon")
        return Vec3(0, 0, -1.62);
    return Vec3::Zero();
}

Material parseMaterial(const ConfigNode &node) {
    Material m;
    m.name = node.text("name", "soil");
    m.youngs_modulus_Pa = node["youngs_modulus_Pa"].positive();
    m.poisson_ratio = node["poisson_ratio"].number();
    m.density_kg_m3 = node["density_kg_m3"].positive();
    node.finish();
    try {
        m.validate();
    } catch (const std::invalid_argument &e) {
        node.fail(e.what());
    }
    return m;
}

/// Runs a model's own parameter check and reports a failure at that model's key.
template <class Model> void validateAt(const ConfigNode &node, const Model &model) {
    try {
        std::visit([](const auto &m) { m.validate(); }, model);
    } catch (const std::invalid_argument &e) {
        node.fail(e.what());
    }
}

/// A slot's parameter: required in `contact`; in `contact_wall` and `contact_tool` (`base` set:
/// the grain-grain slot of the same model) it defaults to the grain-grain value.
double parameter(const ConfigNode &node, const std::string &key, const double *base) {
    return base ? node.number(key, *base) : node[key].number();
}

/// A slot's model: required in `contact`; in a contact type's section it may be left out and
/// must otherwise be the grain-grain model (the types share models, docs/physics.md §2.10).
template <class Slot>
std::string modelOf(const ConfigNode &node, const std::vector<std::string> &choices,
                    const Slot *base) {
    if (!base)
        return node["model"].choice(choices);
    const std::string grains = modelName(*base);
    if (const auto model = node.optional("model"))
        if (model->choice(choices) != grains)
            model->fail("'" + model->text() + "' differs from the grain-grain model '" + grains +
                        "' in 'contact': every contact type uses the grain-grain models with its "
                        "own parameters (a model the grains do not need goes in 'contact' with "
                        "zero parameters)");
    return grains;
}

template <class Model, class Slot> const Model *sameModel(const Slot *base) {
    return base ? std::get_if<Model>(base) : nullptr;
}

DampingModel parseDamping(const ConfigNode &node, const DampingModel *base = nullptr) {
    DampingModel damping;
    if (modelOf(node, {"restitution", "viscous"}, base) == "restitution") {
        const auto *b = sameModel<DampingRestitution>(base);
        damping = DampingRestitution{parameter(node, "restitution", b ? &b->restitution : nullptr)};
    } else {
        const auto *b = sameModel<DampingViscous>(base);
        damping = DampingViscous{
            parameter(node, "coefficient_N_s_m", b ? &b->coefficient_N_s_m : nullptr)};
    }
    node.finish();
    validateAt(node, damping);
    return damping;
}

TangentialModel parseTangential(const ConfigNode &node, const TangentialModel *base = nullptr) {
    TangentialModel tangential;
    if (modelOf(node, {"mindlin", "linear"}, base) == "mindlin") {
        const auto *b = sameModel<TangentialMindlin>(base);
        tangential = TangentialMindlin{
            parameter(node, "friction_coefficient", b ? &b->friction_coefficient : nullptr)};
    } else {
        const auto *b = sameModel<TangentialLinear>(base);
        TangentialLinear t;
        t.stiffness_N_m = parameter(node, "stiffness_N_m", b ? &b->stiffness_N_m : nullptr);
        t.damping_N_s_m = node.number("damping_N_s_m", b ? b->damping_N_s_m : 0.0);
        t.stick_angle_deg = parameter(node, "stick_angle_deg", b ? &b->stick_angle_deg : nullptr);
        // Without its own slip angle a new stick angle is both (the seed's one-angle law).
        const bool own_stick = !b || node.has("stick_angle_deg");
        t.slip_angle_deg =
            node.number("slip_angle_deg", own_stick ? t.stick_angle_deg : b->slip_angle_deg);
        tangential = t;
    }
    node.finish();
    validateAt(node, tangential);
    return tangential;
}

/// A `rolling:` section (contact.rolling, deposition.rolling, a contact type's), §2.6.
RollingModel parseRolling(const ConfigNode &node, const RollingModel *base = nullptr) {
    RollingModel rolling = RollingNone{};
    const std::string model = modelOf(node, {"none", "epsd", "grain_shape"}, base);
    if (model == "epsd") {
        const auto *b = sameModel<RollingEpsd>(base);
        rolling = RollingEpsd{parameter(node, "coefficient", b ? &b->coefficient : nullptr)};
    } else if (model == "grain_shape") {
        // gamma per local axis: one number for all three, or a list of three (§2.6.1).
        const auto *b = sameModel<RollingGrainShape>(base);
        RollingGrainShape shape = b ? *b : RollingGrainShape{};
        if (const auto gamma = b ? node.optional("aspect_ratio_angle_deg")
                                 : std::optional<ConfigNode>(node["aspect_ratio_angle_deg"])) {
            if (gamma->isSequence()) {
                const std::vector<double> values = gamma->numbers();
                if (values.size() != 3)
                    gamma->fail("needs one angle or three (one per local axis), got " +
                                std::to_string(values.size()));
                shape.aspect_ratio_angle_deg = Vec3(values[0], values[1], values[2]);
            } else {
                shape.aspect_ratio_angle_deg.setConstant(gamma->number());
            }
        }
        if (b && node.has("inertia"))
            node["inertia"].fail("the grains' moments of inertia are the grain-grain law's "
                                 "(contact.rolling.inertia), not a contact type's");
        if (const auto inertia = node.optional("inertia"))
            if (inertia->choice({"sphere", "seed_eq12"}) == "seed_eq12")
                shape.inertia = RollingGrainShape::Inertia::SeedEq12;
        rolling = shape;
    }
    node.finish();
    validateAt(node, rolling);
    return rolling;
}

CohesionModel parseCohesion(const ConfigNode &node, const CohesionModel *base = nullptr) {
    CohesionModel cohesion = CohesionNone{};
    if (modelOf(node, {"none", "linear"}, base) == "linear") {
        const auto *b = sameModel<CohesionLinear>(base);
        cohesion = CohesionLinear{
            parameter(node, "energy_density_J_m3", b ? &b->energy_density_J_m3 : nullptr)};
    }
    node.finish();
    validateAt(node, cohesion);
    return cohesion;
}

ContactLaw parseContact(const ConfigNode &node) {
    ContactLaw law;
    law.damping = parseDamping(node["damping"]);
    law.tangential = parseTangential(node["tangential"]);
    if (const auto rolling = node.optional("rolling"))
        law.rolling = parseRolling(*rolling);
    if (const auto cohesion = node.optional("cohesion"))
        law.cohesion = parseCohesion(*cohesion);
    law.background_damping_1_s = node.number("background_damping_1_s", 0.0);
    node.finish();
    try {
        law.finalize();
    } catch (const std::invalid_argument &e) {
        node.fail(e.what());
    }
    return law;
}

/// `contact_wall` or `contact_tool`: the slots that contact type sets for itself.
ContactOverride parseContactOverride(const ConfigNode &node, const ContactLaw &grains) {
    ContactOverride o;
    if (const auto n = node.optional("damping"))
        o.damping = parseDamping(*n, &grains.damping);
    if (const auto n = node.optional("tangential"))
        o.tangential = parseTangential(*n, &grains.tangential);
    if (const auto n = node.optional("rolling"))
        o.rolling = parseRolling(*n, &grains.rolling);
    if (const auto n = node.optional("cohesion"))
        o.cohesion = parseCohesion(*n, &grains.cohesion);
    node.finish();
    try {
        o.appliedTo(grains).finalize();
    } catch (const std::invalid_argument &e) {
        node.fail(e.what());
    }
    return o;
}

void parseWall(const ConfigNode &node, const Material &material, std::vector<PlaneWall> &out) {
    const std::string name = node["name"].text();
    const std::string type = node["type"].choice({"plane", "box"});
    std::optional<double> friction;
    if (const auto f = node.optional("friction_coefficient"))
        friction = f->number();
    if (type == "plane") {
        PlaneWall wall;
        wall.name = name;
        wall.point_m = node["point_m"].vec3();
        wall.normal = node["normal"].vec3();
        if (wall.normal.norm() == 0.0)
            node["normal"].fail("normal must not be zero");
        wall.friction_coefficient = friction;
        wall.material = material;
        if (const auto track = node.optional("track")) {
            FrictionTrack t;
            t.lower_m = (*track)["lower_m"].vec3();
            t.upper_m = (*track)["upper_m"].vec3();
            t.friction_coefficient = (*track)["friction_coefficient"].number();
            track->finish();
            wall.track = t;
        }
        out.push_back(wall);
    } else {
        // Axis-aligned box: six inward-facing planes, the top one optional.
        const Vec3 lo = node["lower_m"].vec3(), hi = node["upper_m"].vec3();
        if ((hi - lo).minCoeff() <= 0.0)
            node["upper_m"].fail("upper_m must exceed lower_m on every axis");
        const bool open_top = node.boolean("open_top", true);
        const char *side[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
        for (int k = 0; k < 6; ++k) {
            if (k == 5 && open_top)
                continue;
            const int axis = k / 2;
            PlaneWall wall;
            wall.name = name + "." + side[k];
            wall.point_m = (k % 2 == 0) ? lo : hi;
            wall.normal = Vec3::Zero();
            wall.normal[axis] = (k % 2 == 0) ? 1.0 : -1.0;
            wall.friction_coefficient = friction;
            wall.material = material;
            out.push_back(wall);
        }
    }
    node.finish();
}

RadiusDistribution parseRadius(const ConfigNode &node) {
    RadiusDistribution d;
    const std::string kind = node["distribution"].choice({"constant", "uniform", "discrete"});
    if (kind == "constant") {
        d.kind = RadiusDistribution::Kind::Constant;
        d.min_m = d.max_m = node["value_m"].positive();
    } else if (kind == "uniform") {
        d.kind = RadiusDistribution::Kind::Uniform;
        d.min_m = node["min_m"].positive();
        d.max_m = node["max_m"].positive();
    } else {
        d.kind = RadiusDistribution::Kind::Discrete;
        d.radii_m = node["radii_m"].numbers();
        d.fractions = node["fractions"].numbers();
    }
    node.finish();
    try {
        d.validate();
    } catch (const std::invalid_argument &e) {
        node.fail(e.what());
    }
    return d;
}

/// Runs a preparation step's own check (a backstop: the keys are checked where they are read).
template <class Spec> void validateSpecAt(const ConfigNode &node, const Spec &spec) {
    try {
        spec.validate();
    } catch (const std::invalid_argument &e) {
        node.fail(e.what());
    }
}

/// deposition.strike_off_height_m, .compaction, .crust (docs/physics.md §6.1). Each is refused
/// where it could change nothing.
void parsePreparation(const ConfigNode &node, DepositionSpec &d) {
    if (const auto h = node.optional("strike_off_height_m")) {
        const double height = h->number();
        const double floor = d.region_lower_m.z();
        const double highest_centre = d.region_upper_m.z() - d.radius.smallest();
        std::ostringstream limits;
        limits.precision(6);
        if (!(height > floor)) {
            limits << "must lie above the bed's floor (region.lower_m z = " << floor << " m)";
            h->fail(limits.str());
        }
        if (height >= highest_centre) {
            limits << "removes nothing: no grain centre can lie above region.upper_m z minus the "
                      "smallest radius = "
                   << highest_centre << " m";
            h->fail(limits.str());
        }
        d.strike_off_height_m = height;
    }
    if (const auto c = node.optional("compaction")) {
        CompactionSpec compaction;
        compaction.pressure_Pa = (*c)["pressure_Pa"].positive();
        if (const auto hold = c->optional("hold_time_s"))
            compaction.hold_time_s = hold->positive();
        if (const auto speed = c->optional("speed_m_s"))
            compaction.speed_m_s = speed->positive();
        c->finish();
        validateSpecAt(*c, compaction);
        d.compaction = compaction;
    }
    if (const auto c = node.optional("crust")) {
        CrustSpec crust;
        crust.thickness_m = (*c)["thickness_m"].positive();
        const ConfigNode factor = (*c)["youngs_modulus_factor"];
        crust.youngs_modulus_factor = factor.positive();
        if (crust.youngs_modulus_factor == 1.0)
            factor.fail("1 changes nothing (the crust would be the soil itself): leave crust out");
        c->finish();
        validateSpecAt(*c, crust);
        crust.material = 1; // makeSystem puts the crust after the soil
        d.crust = crust;
    }
}

TriangleMesh parseMesh(const ConfigNode &node, const std::string &scenario_dir) {
    const std::string type = node["type"].choice({"cylinder", "stl"});
    TriangleMesh mesh;
    if (type == "cylinder") {
        mesh = makeCylinder(node["radius_m"].positive(), node["width_m"].positive(),
                            int(node.integer("segments", 3, kMaxMeshSegments, 72)));
    } else {
        std::string file = node["file"].text();
        if (!file.empty() && file[0] != '/')
            file = scenario_dir + file;
        try {
            mesh = readStl(file);
        } catch (const std::exception &e) {
            node["file"].fail(e.what());
        }
        mesh.transform(node.number("scale", 1.0), Vec3::Zero());
    }
    node.finish();
    return mesh;
}

BodySpec parseBody(const ConfigNode &node, const std::string &scenario_dir) {
    BodySpec b;
    b.name = node["name"].text();
    b.mesh = parseMesh(node["mesh"], scenario_dir);
    b.start.position_m = node["position_m"].vec3();
    if (const auto rot = node.optional("rotation_deg")) {
        const Vec3 r = rot->vec3() * (M_PI / 180.0); // about fixed x, then y, then z
        b.start.orientation = Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) *
                              Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
                              Eigen::AngleAxisd(r.x(), Vec3::UnitX());
    }
    if (const auto c = node.optional("clearance_above_bed_m"))
        b.clearance_above_bed_m = c->number();
    if (const auto f = node.optional("friction_coefficient"))
        b.friction_coefficient = f->number();
    b.record_triangle_loads = node.boolean("record_triangle_loads", false);
    if (const auto motion = node.optional("motion"))
        for (const ConfigNode &seg : motion->items()) {
            MotionSegment m;
            m.duration_s = seg["duration_s"].positive();
            m.linear_velocity_m_s =
                seg.optional("velocity_m_s") ? seg["velocity_m_s"].vec3() : Vec3::Zero();
            m.angular_velocity_rad_s = seg.optional("angular_velocity_rad_s")
                                           ? seg["angular_velocity_rad_s"].vec3()
                                           : Vec3::Zero();
            seg.finish();
            b.motion.push_back(m);
        }
    node.finish();
    return b;
}

} // namespace

DepositionSpec parseDeposition(const ConfigNode &node) {
    DepositionSpec d;
    d.method = node.text("method", "random") == "rain" ? DepositionSpec::Method::Rain
                                                       : DepositionSpec::Method::Random;
    if (const auto m = node.optional("method"))
        m->choice({"random", "rain"});
    const ConfigNode region = node["region"];
    d.region_lower_m = region["lower_m"].vec3();
    d.region_upper_m = region["upper_m"].vec3();
    region.finish();
    if ((d.region_upper_m - d.region_lower_m).minCoeff() <= 0.0)
        region.fail("upper_m must exceed lower_m on every axis");
    d.count = std::size_t(node["count"].integer(1, kMaxGrains));
    d.radius = parseRadius(node["radius"]);
    d.seed = std::uint64_t(node.number("seed", 1.0));
    d.layers = int(node.integer("layers", 1, kMaxLayers, 1));
    d.layer_interval_s = node.number("layer_interval_s", 0.1);
    d.settle_kinetic_energy_J = node.number("settle_kinetic_energy_J", 1e-9);
    d.max_settle_time_s = node.number("max_settle_time_s", 5.0);
    if (const auto rolling = node.optional("rolling"))
        d.rolling = parseRolling(*rolling);
    if (const auto g = node.optional("gravity"))
        d.gravity_m_s2 = gravityOf(*g);
    parsePreparation(node, d);
    node.finish();
    return d;
}

int threadsFor(const ConfigNode &sim) {
    const int given = int(sim.integer("threads", 1, kMaxThreads, 1)); // checked even if overridden
    const auto count = [](const char *text) -> int {
        char *end = nullptr;
        const long n = std::strtol(text, &end, 10);
        return end != text && n >= 1 && n <= kMaxThreads ? int(n) : 0;
    };
    if (const char *forced = std::getenv("GRAINLINK_THREADS")) {
        const int n = count(forced);
        if (n == 0 || *std::find_if(forced, forced + std::strlen(forced),
                                    [](char c) { return c < '0' || c > '9'; }) != '\0')
            throw std::invalid_argument(std::string("--threads / GRAINLINK_THREADS = '") + forced +
                                        "' is not a thread count (1 to " +
                                        std::to_string(kMaxThreads) + ")");
        return n;
    }
    if (sim.has("threads"))
        return given;
    if (const char *omp = std::getenv("OMP_NUM_THREADS")) // "4" or "4,2": the first level
        if (const int n = count(omp))
            return n;
    return 1;
}

DemScenario loadScenario(const std::string &path) {
    DemScenario s = parseScenario(ConfigNode::loadFile(path));
    s.file = path;
    return s;
}

DemScenario parseScenario(const ConfigNode &root, bool coupled) {
    DemScenario s;
    s.name = coupled ? root.text("name", "soil") : root["name"].text();
    // Mesh files are found relative to the scenario file.
    const auto slash = root.file().rfind('/');
    const std::string dir = slash == std::string::npos ? "" : root.file().substr(0, slash + 1);
    const ConfigNode sim = root["simulation"];
    s.settings.time_step_s = sim["time_step_s"].positive();
    s.settings.integrator = sim.text("integrator", "velocity_verlet") == "newmark"
                                ? Integrator::Newmark
                                : Integrator::VelocityVerlet;
    if (const auto i = sim.optional("integrator"))
        i->choice({"velocity_verlet", "newmark"});
    s.settings.newmark_beta = sim.number("newmark_beta", 0.25);
    s.settings.newmark_gamma = sim.number("newmark_gamma", 0.5);
    s.settings.gravity_m_s2 = simulationGravity(sim);
    s.settings.threads = threadsFor(sim);
    s.settings.skin_m = sim.number("skin_m", 0.0);
    s.settings.resort_every_builds = int(sim.integer("resort_every_builds", 0, 1000000, 25));
    s.settings.max_overlap_ratio = sim.number("max_overlap_ratio", 0.4);
    s.settings.check_time_step = sim.boolean("check_time_step", true);
    sim.finish();

    s.material = parseMaterial(root["material"]);
    s.law = parseContact(root["contact"]);
    if (const auto wall = root.optional("contact_wall"))
        s.contact_wall = parseContactOverride(*wall, s.law);
    if (const auto tool = root.optional("contact_tool"))
        s.contact_tool = parseContactOverride(*tool, s.law);
    if (const auto walls = root.optional("walls"))
        for (const ConfigNode &w : walls->items())
            parseWall(w, s.material, s.planes);
    s.deposition = parseDeposition(root["deposition"]);
    // The cache's place: the scenario's key, else GRAINLINK_PACKING_CACHE (one cache for every
    // scenario and folder of a user), else .cache/packings under the working folder.
    const char *cache = std::getenv("GRAINLINK_PACKING_CACHE");
    s.packing_cache_directory =
        root.text("packing_cache_directory", cache ? cache : ".cache/packings");
    if (const auto bodies = root.optional("bodies"))
        for (const ConfigNode &b : bodies->items()) {
            s.bodies.push_back(parseBody(b, dir));
            const std::string implausible =
                implausibleMeshSize(s.bodies.back().mesh, 2.0 * s.deposition.radius.largest(),
                                    (s.deposition.region_upper_m - s.deposition.region_lower_m)
                                        .maxCoeff());
            if (!implausible.empty())
                b["mesh"].fail("body '" + s.bodies.back().name + "': " + implausible);
        }
    if (coupled) {
        s.wall_clearance_m =
            root.number("wall_clearance_m", 2.0 * s.deposition.radius.largest());
        if (!(s.wall_clearance_m >= 0.0))
            root["wall_clearance_m"].fail("must be >= 0 (0: no check)");
        s.bury_bodies = root.boolean("bury_bodies", false);
    } else if (root.has("bury_bodies")) {
        root["bury_bodies"].fail("only a coupled soil (grainlink dem-node) has bodies to bury: "
                                 "remove the key");
    } else if (root.has("wall_clearance_m")) {
        root["wall_clearance_m"].fail("only a coupled soil (grainlink dem-node) watches its bodies' "
                                      "clearance to the walls: remove the key");
    }
    if (!coupled) { // a coupled soil runs as long as the coordinator says
        const ConfigNode run = root["run"];
        s.duration_s = run["duration_s"].positive();
        run.finish();
    }
    if (const auto out = root.optional("output")) {
        s.output.series_interval_s = out->number("series_interval_s", 0.01);
        s.output.snapshot_interval_s = out->number("snapshot_interval_s", 0.0);
        s.output.checkpoint_interval_s = out->number("checkpoint_interval_s", 0.0);
        s.output.contact_network = out->boolean("contact_network", false);
        out->finish();
        if (!(s.output.series_interval_s > 0.0))
            (*out)["series_interval_s"].fail("must be > 0");
    }
    root.finish();
    return s;
}

ContactLaw ContactOverride::appliedTo(ContactLaw law) const {
    if (damping)
        law.damping = *damping;
    if (tangential)
        law.tangential = *tangential;
    if (rolling)
        law.rolling = *rolling;
    if (cohesion)
        law.cohesion = *cohesion;
    return law;
}

Vec3 simulationGravity(const ConfigNode &sim) {
    if (const auto g = sim.optional("gravity_m_s2")) {
        // Both would leave one silently unused (a study varying the vector over a base's name).
        if (sim.has("gravity"))
            g->fail("give gravity or gravity_m_s2, not both (gravity also takes a vector)");
        return g->vec3();
    }
    if (const auto g = sim.optional("gravity"))
        return gravityOf(*g);
    return DemSettings().gravity_m_s2;
}

ContactLaws contactLaws(const DemScenario &s) {
    ContactLaws laws(s.law);
    laws.grain_wall = s.contact_wall.appliedTo(s.law);
    laws.grain_tool = s.contact_tool.appliedTo(s.law);
    return laws;
}

std::unique_ptr<DemSystem> makeSystem(const DemScenario &s) {
    std::vector<Material> materials{s.material};
    if (const auto &crust = s.deposition.crust) {
        if (crust->material != int(materials.size()))
            throw std::logic_error("makeSystem: the crust's material index must follow the soil's");
        materials.push_back(crustMaterial(s.material, *crust));
    }
    auto system = std::make_unique<DemSystem>(contactLaws(s), std::move(materials), s.settings);
    for (const PlaneWall &w : s.planes)
        system->addPlane(w);
    return system;
}

std::string packingKey(const DemScenario &s) {
    std::ostringstream key;
    key.precision(17);
    // The law the grains settle under: rolling laws tested on one packing share its key.
    ContactLaw settling = s.law, settling_wall = s.contact_wall.appliedTo(s.law);
    if (s.deposition.rolling) {
        settling.rolling = settling_wall.rolling = *s.deposition.rolling;
        settling.finalize();
        settling_wall.finalize();
    }
    // v3: a bed is not settled before its top grains could have fallen to the floor (v2 beds
    // under a weak gravity were cut off in free fall; under Earth's the rule rarely binds).
    key << "v3|" << settling.describe() << "|E=" << s.material.youngs_modulus_Pa
        << " nu=" << s.material.poisson_ratio << " rho=" << s.material.density_kg_m3
        << "|dt=" << s.settings.time_step_s << " int=" << int(s.settings.integrator) << ','
        << s.settings.newmark_beta << ',' << s.settings.newmark_gamma
        << " g=" << s.deposition.gravity_m_s2.value_or(s.settings.gravity_m_s2).transpose()
        << " threads=" << s.settings.threads << "|" << s.deposition.describe();
    if (s.contact_wall.any()) // grain-wall contacts shape the packing, grain-tool ones do not
        key << "|contact_wall " << settling_wall.describe();
    for (const PlaneWall &w : s.planes)
        key << "|wall " << w.name << ' ' << w.point_m.transpose() << ' ' << w.normal.transpose()
            << ' ' << w.friction_coefficient.value_or(-1.0);
    return hashKey(key.str());
}

} // namespace grainlink::dem
