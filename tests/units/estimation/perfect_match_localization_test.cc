// The perfect_match_localization unit and its EKF (pose_fusion).
#include <gtest/gtest.h>
