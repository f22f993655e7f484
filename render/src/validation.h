#pragma once
// Input checks that name the field at fault ("frame.spheres[12].radius ...").
#include "rocklab/render/frame.h"

namespace rocklab::render::detail {

/// Throws std::invalid_argument naming the first bad entry of a frame description.
void validateFrame(const FrameDescription& frame);

}  // namespace rocklab::render::detail
