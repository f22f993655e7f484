#pragma once
// Reading a crusher run's results.json for the commands that work on finished runs
// (`rocklab whiten`, `rocklab products`): a key that must be there, and a sieve
// curve (a list of {size_mm, passing}) checked row by row. A complaint is a
// PsdInputError whose message names the key and what is allowed.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace rocklab::experiments::crusher {

struct PsdInputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A finished crusher run's results.json (in `run_dir`), read and checked to hold a
/// `crusher` block; PsdInputError when it cannot be read, is not JSON or has none.
nlohmann::json readCrusherResults(const std::filesystem::path& run_dir);

/// j[key], or PsdInputError "<where>: no key '<key>'".
const nlohmann::json& needKey(const nlohmann::json& j, const std::string& key, const std::string& where);

/// A sieve curve as sizes (mm, increasing, > 0) and fractions passing (0..1).
void readSieveCurve(const nlohmann::json& curve, const std::string& where, std::vector<double>& sizes,
                    std::vector<double>& passing);

}  // namespace rocklab::experiments::crusher
