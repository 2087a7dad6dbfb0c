// The pathtracer command's main (main.cpp holds its body).
#include <string>
#include <vector>

#include "viewer.h"

int main(int argc, char** argv) { return pt::pathtracer_main({argv + 1, argv + argc}, argv[0], nullptr); }
