#pragma once
/// \file The project's one default view: the camera every command uses when none is given, for a volume
/// (its active voxels' box) and for a mesh (its vertices' box) alike, so `render` and `lines` frame the
/// same object the same way. [choice] ParaView's default direction (eye on the +z side of the box centre,
/// up +y), vertical field of view 30 degrees, at the distance where the box's bounding sphere just fits the
/// narrower image axis: the sphere already encloses the box, so no extra margin is added.
#include "core/camera.h"
#include "core/vec.h"

namespace raysift {

/// \param box world-space box to frame; an empty box gets the view of a unit box at the origin.
/// \throw InvalidInput for an image side outside 1..kMaxImageSide.
CameraSpec fit_camera_to_box(const Bbox3d& box, int width = CameraSpec{}.width, int height = CameraSpec{}.height);

}  // namespace raysift
