// second_order's capacity limits, shared by its parameter table (Info.cpp) and its buffers
// (SecondOrder.cpp). GL-free.
#pragma once

namespace gis::second_order {

inline constexpr int kMaxPositive = 1024;
inline constexpr int kMaxNegative = 1024;
/// The discontinuity threshold at which the fix-up is switched off (100% low resolution).
inline constexpr double kNoFixupThreshold = 2.0;

} // namespace gis::second_order
