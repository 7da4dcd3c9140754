// deal.II transversely isotropic elastic model. See fe_model.hpp.
#include "continuum/fe_model.hpp"

#include <deal.II/base/config.h>

namespace rbdem::continuum {

std::string dealii_version() { return DEAL_II_PACKAGE_VERSION; }

}  // namespace rbdem::continuum
