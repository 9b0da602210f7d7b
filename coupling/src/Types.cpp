#include "grainlink/coupling/Types.hpp"

namespace grainlink::coupling {

const char *roleName(Role role) {
    return role == Role::Multibody ? "multibody" : "soil";
}

const char *schemeName(SchemeKind scheme) {
    switch (scheme) {
    case SchemeKind::ExplicitSerial:
        return "explicit-serial";
    case SchemeKind::ExplicitParallel:
        return "explicit-parallel";
    case SchemeKind::Implicit:
        return "implicit";
    }
    return "?";
}

} // namespace grainlink::coupling
