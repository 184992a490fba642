// The FEM service's run over DDS: which bodies it steps, its loop in real
// time (a step every FEM period, each body's newest ContactSet taken) or in
// lockstep (a step per granted FEM period, the ContactSets the read rule
// names), and the lines it prints at its start and end (launchers and tests
// read them). Several deformable bodies are stepped one after the other in
// the scene's order within a period, each with its own ContactSet reader and
// DeformationState writer (the topics are keyed by body; one writer per body
// keeps each instance's sequence and source its own):
// docs/design/two-deformable-bodies.md.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fahr/common/participant.h"
#include "fahr/common/service_reporter.h"
#include "fahr/fem_service/service_step.h"
#include "fahr/scene/scene.h"

namespace fahr::fem_service {

// The scene's deformable bodies, which the service steps, in file order
// (scene::ServicePlan::fem_bodies). Empty when the scene has none: nothing
// to do, said on stdout, exit status 0.
std::vector<std::size_t> choose_bodies(const scene::Scene& scene);

// One ServiceStep per body, in the order choose_bodies gave.
using BodySteps = std::vector<std::unique_ptr<ServiceStep>>;

// Each returns the program's exit status.
int run_realtime(common::Participant& participant, BodySteps& steps, const scene::Scene& scene,
                 common::TickRecorder& recorder, double duration_s);
int run_lockstep(common::Participant& participant, BodySteps& steps, const scene::Scene& scene,
                 common::TickRecorder& recorder);

// The ServiceStatus metrics and errors of all bodies: a single body's under
// their own names, several bodies' as "<body>/<name>" and "body '<body>':
// <error>".
void append_metrics(const BodySteps& steps, std::vector<std::pair<std::string, double>>& out);
void take_errors(BodySteps& steps, std::vector<std::string>& errors);

// One line per body.
void print_start_lines(const common::Participant& participant, const BodySteps& steps,
                       const scene::Scene& scene, bool lockstep);
void print_end_lines(const BodySteps& steps);

}  // namespace fahr::fem_service
