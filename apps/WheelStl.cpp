// `grainlink wheel-stl`: the parametric wheel of a scenario as an STL file, built by the same
// code the soil node uses, so that what a user inspects in a CAD tool is what the grains touch.
#include "Nodes.hpp"
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/WheelMesh.hpp"
#include "grainlink/mbs/WheelTest.hpp"

#include <cstdio>

namespace grainlink::apps {

int exportWheelStl(const std::string &scenario_path, const std::string &stl_path, bool binary) {
    const auto root = config::ConfigNode::loadFile(scenario_path);
    std::optional<config::ConfigNode> block;
    for (const char *model : {"rig", "rover"})
        if (root.has(model) && root[model].has("wheel"))
            block = root[model]["wheel"];
    if (!block)
        root.fail("no `rig.wheel` or `rover.wheel` block to build a wheel from");
    const mbs::WheelShape wheel = mbs::parseWheelShape(*block);
    const dem::TriangleMesh mesh = dem::makeWheel(wheel);
    if (binary)
        dem::writeStlBinary(mesh, stl_path);
    else
        dem::writeStlAscii(mesh, stl_path, "grainlink_wheel");
    std::printf("%s: %zu triangles, wheel %.4g m x %.4g m\n", stl_path.c_str(),
                mesh.triangleCount(), wheel.diameter_m, wheel.width_m);
    return 0;
}

} // namespace grainlink::apps
