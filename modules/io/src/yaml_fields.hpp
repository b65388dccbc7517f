#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <string>

#include "omnislam/io/config.hpp"

// Typed access to one YAML mapping with errors (ConfigError) that name the key and
// file:line (private to io/; the public headers expose plain structs only).

namespace omnislam::io::detail {

[[nodiscard]] inline std::string where(const std::string &file, const YAML::Mark &mark) {
  if (mark.is_null()) return file;
  return file + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

/// One mapping ("section") of a YAML file. read() fills known keys; finish() rejects the
/// keys nobody asked for when the section is strict.
class YamlSection {
 public:
  YamlSection(const YAML::Node &node, std::string prefix, std::string file)
      : node_(node), prefix_(std::move(prefix)), file_(std::move(file)) {
    if (!node_.IsMap()) {
      throw ConfigError(where(file_, node_.Mark()) + ": " +
                        (prefix_.empty() ? "the file" : "'" + prefix_ + "'") + " must be a mapping of keys");
    }
  }

  [[nodiscard]] std::string key_name(const std::string &key) const {
    return prefix_.empty() ? key : prefix_ + "." + key;
  }

  [[nodiscard]] bool has(const std::string &key) {
    seen_.insert(key);
    return static_cast<bool>(node_[key]);
  }

  [[nodiscard]] YAML::Node node(const std::string &key) const { return node_[key]; }
  /// The sub-mapping `key` as a section of its own (its keys named "prefix.key.x").
  [[nodiscard]] YamlSection section(const std::string &key) const {
    return YamlSection(node_[key], prefix_.empty() ? key : prefix_ + "." + key, file_);
  }

  template <typename T>
  void read(const std::string &key, T &value, const char *expected) {
    if (!has(key)) return;
    const YAML::Node field = node_[key];
    try {
      value = field.as<T>();
    } catch (const YAML::Exception &) {
      throw ConfigError(where(file_, field.Mark()) + ": '" + key_name(key) + "' must be " + expected);
    }
  }

  void read(const std::string &key, double &value) {
    read<double>(key, value, "a number");
    if (has(key) && !std::isfinite(value)) fail(key, "must be a finite number");
  }
  void read(const std::string &key, int &value) { read<int>(key, value, "an integer"); }
  void read(const std::string &key, bool &value) { read<bool>(key, value, "true or false"); }
  void read(const std::string &key, std::string &value) { read<std::string>(key, value, "a string"); }

  [[noreturn]] void fail(const std::string &key, const std::string &message) const {
    throw ConfigError(where(file_, node_[key].Mark()) + ": '" + key_name(key) + "' " + message);
  }

  void finish() const {
    for (const auto &entry : node_) {
      if (!entry.first.IsScalar()) {
        throw ConfigError(where(file_, entry.first.Mark()) + ": a key of '" + prefix_ +
                          "' is not a plain name");
      }
      const auto key = entry.first.as<std::string>();
      if (!seen_.contains(key)) {
        throw ConfigError(where(file_, entry.first.Mark()) + ": unknown key '" + key_name(key) + "'");
      }
    }
  }

 private:
  YAML::Node node_;
  std::string prefix_;
  std::string file_;
  std::set<std::string> seen_;
};

/// Reads the sub-mapping `key` of `parent`, if present, with `read(section)`, then rejects
/// any key `read` did not ask for; errors name the full key ("stereo.floor.error_rate").
template <typename Read>
void read_section(YamlSection &parent, const std::string &key, Read &&read) {
  if (!parent.has(key)) return;
  YamlSection section = parent.section(key);
  read(section);
  section.finish();
}

/// A pixel position `key: [u, v]` into u and v.
inline void read_pixel_pair(YamlSection &section, const std::string &key, double &u, double &v) {
  if (!section.has(key)) return;
  const YAML::Node pair = section.node(key);
  if (!pair.IsSequence() || pair.size() != 2) section.fail(key, "must be [u, v] in pixels");
  try {
    u = pair[0].as<double>();
    v = pair[1].as<double>();
  } catch (const YAML::Exception &) {
    section.fail(key, "must be [u, v] in pixels");
  }
}

/// Loads a YAML file, turning parse errors into ConfigError naming file:line.
[[nodiscard]] inline YAML::Node load_yaml(const std::string &file) {
  try {
    return YAML::LoadFile(file);
  } catch (const YAML::BadFile &) {
    throw ConfigError(file + ": cannot open the file");
  } catch (const YAML::ParserException &error) {
    throw ConfigError(where(file, error.mark) + ": " + error.msg);
  }
}

}  // namespace omnislam::io::detail
