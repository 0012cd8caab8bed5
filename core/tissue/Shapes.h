#pragma once
// Simple tissues and reference shapes built by code: discs, spheres, spherical caps, cylinders
// (for the closed-form checks) and a small block of box cells. Units: µm.

#include "mesh/CellComplex.h"

namespace tp {

/// Flat disc of radius a in the plane z = 0 cut from an equilateral lattice of spacing a/rings
/// (so the bending hinges see the mesh they are calibrated on); vertex 0 is the centre. Lattice
/// vertices within a third of a spacing of the rim are moved onto it; every vertex at r ≥ a is
/// clamped. With clampedWidth > 0 the clamped triangles out to r = a + clampedWidth are kept (a
/// built-in edge: zero slope for a plate); otherwise only triangles touching a free vertex.
/// One wall of cell `cell` (−1: a sheet), wound with +z normal.
CellComplex latticeDisc(double a, int rings, double clampedWidth = 0, int cell = -1);

/// Flat disc of radius a, meshed irregularly: the Delaunay triangulation of the centre (vertex 0),
/// points every `spacing` on the rim (and on r = a + clampedWidth), and points thrown at random
/// (fixed seed) at least 0.7·spacing apart. Clamping and kept triangles as latticeDisc.
CellComplex delaunayDisc(double a, double spacing, unsigned seed, double clampedWidth = 0,
                         int cell = -1);

/// Closed sphere of radius R: octahedron subdivided `level` times (8·4^level triangles), vertices
/// projected to the sphere; one cell, wound outward. Vertices on the coordinate axes exist.
CellComplex octaSphere(double R, int level);

/// Spherical cap of sphere radius R centred on the +z pole, of base radius `capRadius` measured
/// in the plane (a latticeDisc mapped onto the sphere at equal geodesic distance, apex at
/// (0, 0, R)); rim clamped. One wall of cell `cell` (−1: a sheet), wound with its normal away
/// from the sphere's centre, so the cell lies below the cap and a pressure inflates it.
CellComplex sphericalCap(double R, double capRadius, int rings, int cell = -1);

/// Flat sheet in z = 0 on an equilateral lattice of spacing ℓ covering about width × height
/// (rows alternate by ℓ/2); a sheet, nothing clamped.
CellComplex flatSheet(double width, double height, double spacing);

/// A block of nx × ny × nz cubic cells of edge `size`, base (z = 0) clamped; every face a wall
/// of two triangles. A small closed cell complex for the command line's first default.
CellComplex boxTissue(int nx, int ny, int nz, double size);

}  // namespace tp
