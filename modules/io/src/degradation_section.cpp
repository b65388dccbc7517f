#include <cstdint>
#include <sstream>
#include <string>

#include "omnislam/io/config.hpp"
#include "yaml_fields.hpp"

// The `degradation:` section of load_config (config.cpp): one sub-mapping per factor.

namespace omnislam::io::detail {
namespace {

void require_range(YamlSection &section, const char *key, double value, double low, double high) {
  if (!(value >= low && value <= high)) {
    std::ostringstream range;
    range << "must be in [" << low << ", " << high << "]";
    section.fail(key, range.str());
  }
}

void read_dust(YamlSection &section, degrade::DustConfig &dust) {
  section.read("enabled", dust.enabled);
  section.read("count", dust.count);
  section.read("min_radius_px", dust.min_radius_px);
  section.read("max_radius_px", dust.max_radius_px);
  section.read("min_opacity", dust.min_opacity);
  section.read("max_opacity", dust.max_opacity);
  section.read("inner_radius_px", dust.inner_radius_px);
  section.read("outer_radius_px", dust.outer_radius_px);
  if (dust.count < 0 || dust.count > 1000) section.fail("count", "must be in 0..1000");
  if (!(dust.min_radius_px > 0.0)) section.fail("min_radius_px", "must be positive");
  if (!(dust.max_radius_px >= dust.min_radius_px)) section.fail("max_radius_px", "must be >= min_radius_px");
  require_range(section, "min_opacity", dust.min_opacity, 0.0, 1.0);
  require_range(section, "max_opacity", dust.max_opacity, dust.min_opacity, 1.0);
  if (dust.inner_radius_px < 0.0) section.fail("inner_radius_px", "must be >= 0");
  if (!(dust.outer_radius_px > dust.inner_radius_px)) {
    section.fail("outer_radius_px", "must exceed inner_radius_px");
  }
}

}  // namespace

void read_degradation(YamlSection &section, degrade::DegradationConfig &config) {
  section.read<std::uint64_t>("seed", config.seed, "a non-negative integer");
  read_pixel_pair(section, "center_px", config.center_u_px, config.center_v_px);
  read_section(section, "exposure", [&](YamlSection &exposure) {
    exposure.read("enabled", config.exposure.enabled);
    exposure.read("max_change", config.exposure.max_change);
    if (!(config.exposure.max_change >= 0.0 && config.exposure.max_change < 1.0)) {
      exposure.fail("max_change", "must be in [0, 1)");
    }
  });
  read_section(section, "vignetting", [&](YamlSection &vignetting) {
    vignetting.read("enabled", config.vignetting.enabled);
    vignetting.read("rim_falloff", config.vignetting.rim_falloff);
    vignetting.read("rim_radius_px", config.vignetting.rim_radius_px);
    require_range(vignetting, "rim_falloff", config.vignetting.rim_falloff, 0.0, 1.0);
    if (!(config.vignetting.rim_radius_px > 0.0)) vignetting.fail("rim_radius_px", "must be positive");
  });
  read_section(section, "dust", [&](YamlSection &dust) { read_dust(dust, config.dust); });
  read_section(section, "blur", [&](YamlSection &blur) {
    blur.read("enabled", config.blur.enabled);
    blur.read("radius_px", config.blur.radius_px);
    require_range(blur, "radius_px", config.blur.radius_px, 0.0, 20.0);
  });
  read_section(section, "noise", [&](YamlSection &noise) {
    noise.read("enabled", config.noise.enabled);
    noise.read("full_well_e", config.noise.full_well_e);
    noise.read("read_noise_dn", config.noise.read_noise_dn);
    if (!(config.noise.full_well_e > 0.0)) noise.fail("full_well_e", "must be positive");
    if (config.noise.read_noise_dn < 0.0) noise.fail("read_noise_dn", "must be >= 0");
  });
  read_section(section, "jpeg", [&](YamlSection &jpeg) {
    jpeg.read("enabled", config.jpeg.enabled);
    jpeg.read("quality", config.jpeg.quality);
    if (config.jpeg.quality < 1 || config.jpeg.quality > 100) jpeg.fail("quality", "must be in 1..100");
  });
}

}  // namespace omnislam::io::detail
