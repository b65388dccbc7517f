#pragma once

#include <Eigen/Core>
#include <vector>

#include "omnislam/stereo/local_scan.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"

/// @file
/// Floor contacts ranged by stereo with outer twins chosen without the configured level,
/// for measuring the floor (calib/level_fit.hpp: the rig's tilt off level). The
/// floor-boundary search takes a contact's outer twin as the outer edge nearest the row the
/// configured floor puts it at; where the outer lobe shows several edges there (planks, a
/// skirting board's top and base), that choice follows the configuration, and so would a
/// floor measured from it. Here a contact counts only when one outer edge of its polarity
/// lies anywhere the floor could put it were the floor tilted by up to a given angle either
/// way: which edge is its twin then does not depend on the configured tilt.

namespace omnislam::stereo {

/// Each floor contact (not elevated) of `scan`, which `reconstructor` has just reconstructed
/// (its lobes' edges are that frame's), whose outer lobe has exactly one edge of the inner
/// edge's polarity between the rows where the floor point at the contact's inner row would
/// appear with the floor turned by -`max_tilt_rad` and +`max_tilt_rad` about the axis
/// across its azimuth; triangulated by stereo with that edge. Points in the configured
/// level frame, metres, the pinhole at the origin, z up.
[[nodiscard]] std::vector<Eigen::Vector3d> unambiguous_floor_contacts(const ScanReconstructor &reconstructor,
                                                                      const LocalScan &scan,
                                                                      double max_tilt_rad);

}  // namespace omnislam::stereo
