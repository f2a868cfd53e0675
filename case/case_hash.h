// Which case inputs a stored field depends on, and a stable digest of them. A field file
// records the hash; a stage regenerates the field only when the hash of the current case
// differs (and can say which key changed by comparing field_inputs()). The same for the
// whole case (case_inputs), which a DEM checkpoint records.
#pragma once

#include "case/case_model.h"

#include <string>
#include <utility>
#include <vector>

namespace magbrush {

enum class FieldKind
{
  magnetic,
  electric
};

// Canonical "key path" -> value (SI, full precision) of every input the field depends on,
// as marked in the schema (case_schema.h). A non-magnetic blade (mu_r = 1) does not enter the
// magnetic inputs: moving it does not change the roller field.
std::vector<std::pair<std::string, std::string>> field_inputs(const Case &c, FieldKind k);

// FNV-1a 64-bit digest of field_inputs as 16 hex digits.
std::string field_hash(const Case &c, FieldKind k);

// Every input that changes a stored field (magnetic or electric), blades included: the Gmsh
// meshes are built from a subset of these, so `magbrush mesh` rewrites a mesh only when this
// digest changed (a superset of the mesh's inputs: never stale, sometimes remeshed needlessly).
std::string mesh_hash(const Case &c);

// Every resolved input of the case, "key path" -> value (SI, full precision), in schema
// order: the identity of a case, which a DEM checkpoint carries (dem/checkpoint_file.h).
std::vector<std::pair<std::string, std::string>> case_inputs(const Case &c);
// FNV-1a 64-bit digest of case_inputs as 16 hex digits.
std::string case_hash(const Case &c);

} // namespace magbrush
