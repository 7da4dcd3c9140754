// Continuum twin of the DEM specimen: deal.II transversely isotropic linear elasticity on the same TriMesh.
// This header is deal.II-free so that callers do not pay deal.II's compile cost.
#pragma once

#include <string>

namespace rbdem::continuum {

// The deal.II version the model was built with (a smoke check that the library links).
std::string dealii_version();

}  // namespace rbdem::continuum
