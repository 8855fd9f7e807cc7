#pragma once
/// \file io/generate.hpp
/// The former home of the generator and the tetrahedralizer, now in tethash::meshing: the old names,
/// kept for code not yet moved to the meshing headers. New code includes tethash/meshing/*.hpp.
#include "tethash/io/surface.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/meshing/tetrahedralize.hpp"
#include "tethash/meshing/winding_number.hpp"

namespace tethash::io {

using meshing::generate;
using meshing::generate_shapes;
using meshing::GenerateParams;
using meshing::shape_catalog;
using meshing::shape_natural_size;
using meshing::ShapeInfo;
using meshing::tetrahedralize;
using meshing::tetrahedralize_sdf;
using meshing::TetrahedralizeParams;
using meshing::winding_numbers;

} // namespace tethash::io
