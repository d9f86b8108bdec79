// A flag whose value is one of an enum's names: what the --encoding and --rotation-blend flags
// share. Header-only; the clients link CLI11.
#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <string>

namespace deform::cli {

// The name `names` gives `value`, or `fallback` when it gives none.
template <typename Enum>
std::string NameOf(const std::map<std::string, Enum>& names, Enum value,
                   const std::string& fallback) {
  for (const auto& [name, named] : names) {
    if (named == value) return name;
  }
  return fallback;
}

// Adds `flag` to `app`, read into *value as one of `names` (in any case); the help shows
// `default_name` as the default.
template <typename Enum>
CLI::Option* AddEnumFlag(CLI::App& app, const std::string& flag, Enum* value,
                         const std::map<std::string, Enum>& names, const std::string& help,
                         const std::string& default_name) {
  return app.add_option(flag, *value, help)
      ->transform(CLI::CheckedTransformer(names, CLI::ignore_case))
      ->default_str(default_name);
}

}  // namespace deform::cli
