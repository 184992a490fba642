// The outer shell of a service main: runs it and turns the errors a user
// can cause (bad scene, bad transport settings) into a message and exit
// status 2, anything else into status 1.
#pragma once

namespace fahr::runtime {

int run_service_main(const char* service_name, int (*run)(int argc, char** argv), int argc,
                     char** argv);

}  // namespace fahr::runtime
