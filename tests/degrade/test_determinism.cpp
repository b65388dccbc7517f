#include <catch2/catch.hpp>
#include <opencv2/core.hpp>
#include <thread>
#include <vector>

#include "degrade_helpers.hpp"

using namespace omnislam::degrade;
using namespace omnislam::degrade::test;

namespace {

cv::Mat textured() {
  cv::Mat image(1024, 1024, CV_8UC1);
  cv::setRNGSeed(7);
  cv::randu(image, 30, 220);
  return image;
}

}  // namespace

TEST_CASE("degrade: 'none' returns the input byte for byte", "[degrade]") {
  const cv::Mat image = textured();
  const Degraded out = degrade(image, only("none"), 3);
  REQUIRE(out.ok());
  CHECK(identical(out.image, image));
  CHECK(out.image.data != image.data);  // a copy, not a view of the caller's pixels
  CHECK(out.exposure_gain == 1.0);
}

TEST_CASE("degrade: a frame's bytes depend on (seed, frame) only, not on order or thread", "[degrade]") {
  const cv::Mat image = textured();
  const Degrader degrader(DegradationConfig{}, image.size());
  std::vector<cv::Mat> in_sequence;
  for (int frame = 1; frame <= 3; ++frame) in_sequence.push_back(degrader.apply(image, frame).image);

  // Frame 3 alone, from a fresh degrader, and frames 3 and 1 on two threads at once.
  CHECK(identical(degrade(image, DegradationConfig{}, 3).image, in_sequence[2]));
  cv::Mat third, first;
  std::thread a([&] { third = degrader.apply(image, 3).image; });
  std::thread b([&] { first = degrader.apply(image, 1).image; });
  a.join();
  b.join();
  CHECK(identical(third, in_sequence[2]));
  CHECK(identical(first, in_sequence[0]));

  CHECK_FALSE(identical(in_sequence[0], in_sequence[1]));  // another frame: other noise
  DegradationConfig other_seed;
  other_seed.seed = 2;
  CHECK_FALSE(identical(degrade(image, other_seed, 1).image, in_sequence[0]));
}

TEST_CASE("degrade: noise differs between frames, dust stays where it is", "[degrade]") {
  const cv::Mat image = flat(150);
  const Degrader noisy(only("noise"), image.size());
  const cv::Mat one = noisy.apply(image, 1).image, two = noisy.apply(image, 2).image;
  const double changed = cv::countNonZero(one != two) / static_cast<double>(image.total());
  CHECK(changed > 0.5);  // noise of ~3 DN: most pixels differ between frames

  const Degrader dusty(only("dust"), image.size());
  const cv::Mat dust_one = dusty.apply(image, 1).image;
  CHECK(cv::countNonZero(dust_one != image) > 0);
  for (int frame : {2, 17, 1000}) CHECK(identical(dusty.apply(image, frame).image, dust_one));
  // The same specks under noise and for any frame: the gain map depends on the seed only.
  const Degrader all_factors(DegradationConfig{}, image.size());
  CHECK(identical(all_factors.gain_map(), Degrader(only("vignetting,dust"), image.size()).gain_map()));
  DegradationConfig other_seed = only("dust");
  other_seed.seed = 99;
  CHECK_FALSE(identical(Degrader(other_seed, image.size()).gain_map(), dusty.gain_map()));
}
