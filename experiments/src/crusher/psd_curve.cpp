#include "crusher/psd_curve.h"

#include <fstream>

namespace rocklab::experiments::crusher {

nlohmann::json readCrusherResults(const std::filesystem::path& run_dir) {
  std::ifstream in(run_dir / "results.json");
  if (!in) throw PsdInputError("cannot read (a crusher run's folder holds it)");
  nlohmann::json r;
  try {
    r = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw PsdInputError(std::string("not JSON: ") + e.what());
  }
  needKey(r, "crusher", "results.json (not a crusher run)");
  return r;
}

const nlohmann::json& needKey(const nlohmann::json& j, const std::string& key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw PsdInputError(where + ": no key '" + key + "'");
  return j.at(key);
}

void readSieveCurve(const nlohmann::json& curve, const std::string& where, std::vector<double>& sizes,
                    std::vector<double>& passing) {
  if (!curve.is_array() || curve.size() < 2)
    throw PsdInputError(where + ": must list at least two {size_mm, passing}");
  for (const nlohmann::json& point : curve) {
    const nlohmann::json& s = needKey(point, "size_mm", where);
    const nlohmann::json& p = needKey(point, "passing", where);
    if (!s.is_number() || !p.is_number() || !(p.get<double>() >= 0 && p.get<double>() <= 1) || !(s.get<double>() > 0))
      throw PsdInputError(where + ": size_mm must be > 0 and passing within 0 and 1, got " + point.dump());
    if (!sizes.empty() && !(s.get<double>() > sizes.back())) throw PsdInputError(where + ": sizes must increase");
    sizes.push_back(s.get<double>());
    passing.push_back(p.get<double>());
  }
}

}  // namespace rocklab::experiments::crusher
