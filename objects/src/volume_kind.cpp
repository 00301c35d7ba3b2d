#include "dyncull/objects/volume_kind.hpp"

namespace dyncull {

const char* toString(VolumeKind k) {
    switch (k) {
        case VolumeKind::Aabb: return "aabb";
        case VolumeKind::Obb: return "obb";
        case VolumeKind::Kdop14: return "kdop14";
        case VolumeKind::Kdop18: return "kdop18";
        case VolumeKind::Kdop26: return "kdop26";
    }
    return "?";
}

const char* toString(VolumeChoice c) {
    return c == VolumeChoice::Auto ? "auto" : toString(kindOf(c));
}

VolumeKind kindOf(VolumeChoice c) {
    assert(c != VolumeChoice::Auto);
    return static_cast<VolumeKind>(c);
}

Expected<VolumeChoice> parseVolumeChoice(const std::string& s) {
    for (int i = 0; i <= static_cast<int>(VolumeChoice::Auto); ++i) {
        const auto c = static_cast<VolumeChoice>(i);
        if (s == toString(c)) return c;
    }
    return Error{"unknown volume '" + s + "' (expected aabb, obb, kdop14, kdop18, kdop26 or auto)"};
}

}  // namespace dyncull
