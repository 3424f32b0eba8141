#include "rig.h"

#include <set>

#include "input_error.h"

namespace stereorig {

namespace {

bool PosesAgree(const Pose& a, const Pose& b) {
  return (a.rotation() - b.rotation()).cwiseAbs().maxCoeff() <= kSRotationTolerance &&
         (a.translation_mm() - b.translation_mm()).cwiseAbs().maxCoeff() <= kSTranslationToleranceMm;
}

std::string Entry(int i, int j) { return "S[" + std::to_string(i) + "][" + std::to_string(j) + "]"; }

}  // namespace

Rig::Rig(std::vector<Camera> cameras, std::vector<std::string> camera_names, std::vector<StereoModule> modules,
         const std::vector<Pose>& module0_from_module)
    : cameras_(std::move(cameras)), camera_names_(std::move(camera_names)), modules_(std::move(modules)) {
  CheckTopology("rig");
  const int m = num_modules();
  STEREORIG_CHECK(static_cast<int>(module0_from_module.size()) == m);
  S_.assign(m, std::vector<Pose>(m));
  for (int i = 0; i < m; ++i) {
    const Pose module_i_from_module0 = module0_from_module[i].Inverse();
    for (int j = 0; j < m; ++j) S_[i][j] = i == j ? Pose::Identity() : module_i_from_module0 * module0_from_module[j];
  }
  std::string why;
  STEREORIG_CHECK(CheckS(&why));
}

Rig::Rig(std::vector<Camera> cameras, std::vector<std::string> camera_names, std::vector<StereoModule> modules,
         std::vector<std::vector<Pose>> S, const std::string& where)
    : cameras_(std::move(cameras)),
      camera_names_(std::move(camera_names)),
      modules_(std::move(modules)),
      S_(std::move(S)),
      source_(where) {
  CheckTopology(where);
  if (static_cast<int>(S_.size()) != num_modules()) {
    throw InputError(where, "S has " + std::to_string(S_.size()) + " rows but the rig has " +
                                std::to_string(num_modules()) + " modules");
  }
  for (const auto& row : S_) {
    if (static_cast<int>(row.size()) != num_modules()) throw InputError(where, "S is not M x M");
  }
  std::string why;
  if (!CheckS(&why)) throw InputError(where, why);
}

void Rig::CheckTopology(const std::string& where) const {
  if (cameras_.empty()) throw InputError(where, "the rig has no cameras");
  if (modules_.empty()) throw InputError(where, "the rig has no modules (M must be >= 1)");
  if (camera_names_.size() != cameras_.size()) throw InputError(where, "one name per camera is required");
  std::set<int> used;
  for (size_t i = 0; i < modules_.size(); ++i) {
    const StereoModule& m = modules_[i];
    for (int c : {m.left_camera, m.right_camera}) {
      if (c < 0 || c >= num_cameras()) {
        throw InputError(
            where, "module " + std::to_string(i) + " names camera " + std::to_string(c) + ", which does not exist");
      }
      if (!used.insert(c).second) {
        throw InputError(where, "camera " + std::to_string(c) + " belongs to more than one module slot");
      }
    }
    std::string why;
    if (!IsRigid(m.right_from_left.ToMatrix4(), kSRotationTolerance, &why)) {
      throw InputError(where, "module " + std::to_string(i) + " right_from_left: " + why);
    }
  }
  if (static_cast<int>(used.size()) != num_cameras()) {
    std::string unused;  // named, so that a module left out of a hand-edited file is found
    for (int c = 0; c < num_cameras(); ++c)
      if (!used.count(c)) unused += (unused.empty() ? "" : ", ") + std::to_string(c);
    throw InputError(where, "every camera must belong to exactly one module: camera(s) " + unused + " in none");
  }
}

bool Rig::CheckS(std::string* why) const {
  const int m = num_modules();
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      std::string r;
      if (!IsRigid(S_[i][j].ToMatrix4(), kSRotationTolerance, &r)) {
        if (why) *why = Entry(i, j) + ": " + r;
        return false;
      }
    }
    if (!PosesAgree(S_[i][i], Pose::Identity())) {
      if (why) *why = Entry(i, i) + " is not the identity";
      return false;
    }
  }
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      if (!PosesAgree(S_[j][i], S_[i][j].Inverse())) {
        if (why) *why = Entry(j, i) + " is not the inverse of " + Entry(i, j);
        return false;
      }
      for (int k = 0; k < m; ++k) {
        if (!PosesAgree(S_[i][j] * S_[j][k], S_[i][k])) {
          if (why) *why = Entry(i, j) + " * " + Entry(j, k) + " != " + Entry(i, k) + " (S is not consistent)";
          return false;
        }
      }
    }
  }
  return true;
}

Pose Rig::CamFromReference(int camera_index) const {
  for (int i = 0; i < num_modules(); ++i) {
    const StereoModule& m = modules_[i];
    if (m.left_camera == camera_index) return S_[i][0];
    if (m.right_camera == camera_index) return m.right_from_left * S_[i][0];
  }
  STEREORIG_CHECK(false && "camera belongs to no module");
  return Pose();
}

}  // namespace stereorig
