// Public API: `umbmark plan` as one call.
//   api::Plan(api::PlanOptions) -> api::PlanResult; api::ToJson(result) is
//   the command's --json document; api::PlanMotionsJson /
//   api::WritePlanMotions its --motions file.
//   api::PlanCheck(api::PlanCheckOptions) -> api::PlanCheckResult is
//   `plan --check`, api::ToJson(result) its --json document.
#pragma once

#include "api/plan.hpp"
#include "umbmark/io.hpp"
