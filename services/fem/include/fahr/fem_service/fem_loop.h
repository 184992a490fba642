// The FEM service's run over DDS: which body it steps, its loop in real time
// (a step every FEM period, the newest ContactSet taken) or in lockstep (a
// step per granted FEM period, the ContactSet the read rule names), and the
// lines it prints at its start and end (launchers and tests read them).
#pragma once

#include <cstddef>
#include <optional>

#include "fahr/common/participant.h"
#include "fahr/common/service_reporter.h"
#include "fahr/fem_service/service_step.h"
#include "fahr/scene/scene.h"

namespace fahr::fem_service {

// The scene's one deformable body, which the service steps. None when the
// scene has no deformable body (nothing to do: exit status 0) or more than
// one (exit status 2); either is said on stdout or stderr.
struct BodyChoice {
  std::optional<std::size_t> body;
  int exit_status = 0;
};
BodyChoice choose_body(const scene::Scene& scene);

// Each returns the program's exit status.
int run_realtime(common::Participant& participant, ServiceStep& fem_step, const scene::Scene& scene,
                 common::TickRecorder& recorder, double duration_s);
int run_lockstep(common::Participant& participant, ServiceStep& fem_step, const scene::Scene& scene,
                 common::TickRecorder& recorder);

void print_start_line(const common::Participant& participant, const FemBodySetup& setup,
                      const scene::Scene& scene, bool lockstep);
void print_end_line(const ServiceStep& fem_step);

}  // namespace fahr::fem_service
