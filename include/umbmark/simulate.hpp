// Public facade: synthetic campaigns with the contract's effects.
//   api::Simulate(api::SimulateOptions) -> api::SimulateResult: `umbmark
//   simulate` as one call (writes the campaign); api::ToJson(result).
//   sim::SimulateCampaign(manifest, options) -> SimulatedCampaign;
//   io::WriteCampaign writes it; sim::CampaignTruthJson describes the truth.
#pragma once

#include "api/simulate.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"
#include "umbmark/io.hpp"
