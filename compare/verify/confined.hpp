// The confined compression of `rbdem verify`'s slope cases (strength.triaxial_slope in cases_strength.cpp,
// strength3.triaxial_slope in cases_3d.cpp): the scene's dip study as triaxial tests at sigma_3 = 0 and 10 MPa (the
// axis `sigma3_mpa`); the caller sets the dips and the realizations.
#pragma once

#include <string>

#include "dem/scene.hpp"
#include "study/study.hpp"

namespace rbdem::verify {

study::StudySpec confined_spec(const Scene& scene, const std::string& name);

}  // namespace rbdem::verify
