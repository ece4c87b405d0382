#pragma once
// Character import (glTF 2.0 .glb/.gltf, FBX, and whatever else assimp reads that carries a skin) into
// swish::Character: skeleton, skinned body, garment (game mesh) and an optional separate simulation
// mesh, in the rest pose, metres, Y up.
//
// The rest pose is the pose of the skeleton's nodes in the file. Skinned vertices are put there through
// the file's own bind matrices (v_rest = sum_k w_k * G_k * IBM_k * v), so a file whose bind pose differs
// from its node pose still imports consistently; the Character's inverse bind matrices are then the
// inverses of the rest globals (for files like ../shared/assets/tshirt_lo.glb, whose bind pose is the
// node pose, that is exactly the file's matrices).
#include <filesystem>
#include <string>
#include <vector>

#include "swish/core/character.hpp"

namespace swish::io {

struct CharacterImportOptions {
  // Meshes are picked by mesh or node name, case-insensitively; the first name in a list that matches
  // wins. All primitives/sub-meshes of the chosen mesh are merged.
  std::vector<std::string> bodyNames = {"body", "mannequin", "skin"};
  std::vector<std::string> garmentNames = {"garment", "shirt", "jersey", "tshirt", "t-shirt", "cloth"};
  // Optional; when none matches, Character::simulationMesh stays empty.
  std::vector<std::string> simulationMeshNames = {"simulation", "garment_sim", "shirt_hi",
                                                  "shirt_sim",  "jersey_hi",   "jersey_sim"};
  // Joints that must exist (Error naming the missing ones otherwise).
  std::vector<std::string> requiredJoints = defaultInputJointNames();
  // Check the garment's (and simulation mesh's) topology: manifold edges, consistent winding, outward
  // orientation (see mesh_topology_check.hpp).
  bool checkGarmentTopology = true;
};

// Throws swish::Error naming the file and the problem: missing or unreadable file, corrupt file, no
// body/garment mesh (listing the meshes there are), mesh without skin, vertex without weights,
// missing joints, non-manifold or inverted garment.
Character importCharacter(const std::filesystem::path& file, const CharacterImportOptions& options = {});

}  // namespace swish::io
