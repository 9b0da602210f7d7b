#include "grainlink/body/WheelShape.hpp"

#include <cmath>
#include <string>

namespace grainlink::body {

WheelShape parseWheelShape(const config::ConfigNode &w) {
    // Every key changes the mesh the grains touch; one that would not (a grouser's height
    // without grousers) is an error, not silently dropped.
    WheelShape shape;
    shape.diameter_m = w["diameter_m"].positive();
    shape.width_m = w["width_m"].positive();
    shape.closed_sides = w.boolean("closed_sides", true);
    if (const auto t = w.optional("rim_thickness_m")) {
        if (shape.closed_sides)
            t->fail("a closed wheel is solid to the grains, so its rim takes no thickness: give "
                    "it to an open wheel (closed_sides: false) or remove the key");
        shape.rim_thickness_m = t->positive();
        if (!(shape.rim_thickness_m < 0.5 * shape.diameter_m))
            t->fail("must be less than the rim radius, " + std::to_string(0.5 * shape.diameter_m) +
                    " m");
    }
    shape.grouser_count = unsigned(w.integer("grouser_count", 0, kMaxGrousers, 0));
    if (shape.grouser_count == 0) {
        for (const char *key :
             {"grouser_height_m", "grouser_thickness_m", "grouser_shape", "chevron_angle_deg"})
            if (w.has(key))
                w[key].fail("a wheel without grousers (grouser_count 0) has no grouser shape: "
                            "set grouser_count or remove the key");
        w.finish();
        return shape;
    }
    shape.grouser_height_m = w["grouser_height_m"].positive();
    shape.grouser_thickness_m = w["grouser_thickness_m"].positive();
    if (w.has("grouser_shape") && w["grouser_shape"].choice({"straight", "chevron"}) == "chevron")
        shape.grouser_shape = GrouserShape::Chevron;
    if (const auto angle = w.optional("chevron_angle_deg")) {
        if (shape.grouser_shape != GrouserShape::Chevron)
            angle->fail("straight grousers have no sweep angle: set grouser_shape: chevron or "
                        "remove the key");
        shape.chevron_angle_deg = angle->number();
        if (!(std::abs(shape.chevron_angle_deg) < 80.0))
            angle->fail("must lie in (-80, 80) degrees");
    }
    w.finish();
    return shape;
}

} // namespace grainlink::body
