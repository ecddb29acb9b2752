// Public facade: synthetic campaigns with the contract's effects.
//   sim::SimulateCampaign(manifest, options) -> SimulatedCampaign;
//   io::WriteCampaign writes it; sim::CampaignTruthJson describes the truth.
#pragma once

#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"
#include "umbmark/io.hpp"
