#include <catch2/catch.hpp>
#include <string>

#include "omnislam/degrade/degradation_config.hpp"

using namespace omnislam::degrade;

TEST_CASE("degrade: factor lists all, none and names select the factors", "[degrade]") {
  DegradationConfig config;
  CHECK(enabled_factors(config) == "exposure,vignetting,dust,blur,noise,jpeg");
  CHECK(apply_factor_list("all", config).empty());
  CHECK(enabled_factors(config) == "exposure,vignetting,dust,blur,noise,jpeg");

  DegradationConfig some;
  CHECK(apply_factor_list(" jpeg, noise ,blur", some).empty());
  CHECK(enabled_factors(some) == "blur,noise,jpeg");  // application order, not list order
  CHECK_FALSE(some.exposure.enabled);
  CHECK_FALSE(some.dust.enabled);

  DegradationConfig none;
  CHECK(apply_factor_list("none", none).empty());
  CHECK(enabled_factors(none) == "none");

  // A factor switched off in the configuration stays off even when listed.
  DegradationConfig no_jpeg;
  no_jpeg.jpeg.enabled = false;
  CHECK(apply_factor_list("all", no_jpeg).empty());
  CHECK(enabled_factors(no_jpeg) == "exposure,vignetting,dust,blur,noise");
}

TEST_CASE("degrade: a bad factor list names the entry and the valid names", "[degrade]") {
  DegradationConfig config;
  const std::string unknown = apply_factor_list("noise,smudge", config);
  CHECK_THAT(unknown, Catch::Contains("'smudge'") &&
                          Catch::Contains("all, none, or a comma-separated list of exposure, vignetting, "
                                          "dust, blur, noise, jpeg"));
  CHECK(enabled_factors(config) == "exposure,vignetting,dust,blur,noise,jpeg");  // unchanged
  CHECK_THAT(apply_factor_list("noise,,blur", config), Catch::Contains("empty degradation factor"));
  CHECK_THAT(apply_factor_list("", config), Catch::Contains("empty degradation factor"));
  CHECK_THAT(apply_factor_list("all,noise", config), Catch::Contains("unknown degradation factor 'all'"));
  CHECK_THAT(apply_factor_list("Noise", config), Catch::Contains("'Noise'"));
}
