#pragma once
/// \file io/vega.hpp
/// Vega .veg (*VERTICES, *ELEMENTS TET; other sections skipped). ASCII; '#' starts a comment.
/// Errors: "FILE:LINE: expected X, found Y".
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

namespace tethash::io {

/// *VERTICES ("n 3 0 0", lines "id x y z", ids 1..n) and *ELEMENTS with type TET ("m 4 0", 1-based);
/// other sections are skipped; *INCLUDE and element types other than TET are errors. No labels.
TetMesh read_veg(const std::string& path, ReadNotes* notes = nullptr);

} // namespace tethash::io
