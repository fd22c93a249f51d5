#pragma once
/// \file The binding groups of raysift._raysift, one per file.
#include <pybind11/pybind11.h>

namespace raysift::py {

void bind_volumes(pybind11::module_& m);  ///< Volume, TransferFunction, Camera (py_volume.cpp)
void bind_render(pybind11::module_& m);   ///< Renderer, render (py_render.cpp)
void bind_tools(pybind11::module_& m);    ///< compare, mesh, lines, read_image, write_image (py_tools.cpp)
void bind_sweep(pybind11::module_& m);    ///< the rows of sweep (py_sweep.cpp; the dicts in __init__.py)

}  // namespace raysift::py
