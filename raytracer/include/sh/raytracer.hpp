#pragma once
// The stream ray tracer: scenes, the uniform grid, the DSL kernels and the
// renderer that runs them on any backend.
#include "sh/raytracer/bidirectional.hpp"
#include "sh/raytracer/grid.hpp"
#include "sh/raytracer/kernels.hpp"
#include "sh/raytracer/render.hpp"
#include "sh/raytracer/scene.hpp"
#include "sh/raytracer/solid_angle.hpp"
