#pragma once
// Where the shipped data live at run time.

#include <string>

namespace tp {

/// The shipped default tissue: $TISSUEPROBE_DEFAULT_TISSUE if set, else meshes/default.ply next
/// to the executable's build tree (bin/../../meshes) or in the source tree. Throws
/// std::runtime_error listing the places tried when none exists.
std::string defaultTissuePath();

}  // namespace tp
