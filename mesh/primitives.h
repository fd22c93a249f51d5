#pragma once
/// \file Analytic triangle meshes for tests, examples and benchmarks: icosphere, open cylinder, torus and
/// plane. All are counter-clockwise seen from outside (normals point away from the solid; the plane's
/// towards +z) and have exact vertex positions on the analytic surface.
#include "core/vec.h"
#include "core/tri_mesh.h"

namespace raysift::mesh {

/// Subdivided icosahedron projected to the sphere: 20·4^subdivisions triangles.
/// \throw InvalidInput unless radius > 0 and 0 <= subdivisions <= 8.
TriMesh make_icosphere(double radius, int subdivisions, const Vec3d& center = {});

/// Open cylinder around the z axis, z in [-height/2, height/2]; n_around × n_along quads, split in two.
/// \throw InvalidInput unless radius, height > 0, n_around >= 3 and n_along >= 1.
TriMesh make_cylinder(double radius, double height, int n_around, int n_along);

/// Torus around the z axis: ((R + r cos v) cos u, (R + r cos v) sin u, r sin v), n_major × n_minor quads.
/// \throw InvalidInput unless major_radius > minor_radius > 0, n_major >= 3 and n_minor >= 3.
TriMesh make_torus(double major_radius, double minor_radius, int n_major, int n_minor);

/// Square grid in the plane z = 0 centred at the origin, side `size`, n × n quads, normal +z.
/// \throw InvalidInput unless size > 0 and n >= 1.
TriMesh make_plane(double size, int n);

}  // namespace raysift::mesh
