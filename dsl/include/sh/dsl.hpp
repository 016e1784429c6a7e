#pragma once
// The language: values, operators, library, control flow, programs, tables,
// channels and the backend interface, with the reference interpreter.
#include "sh/accumulator.hpp"
#include "sh/attrib.hpp"
#include "sh/backend.hpp"
#include "sh/channel.hpp"
#include "sh/control.hpp"
#include "sh/error.hpp"
#include "sh/library.hpp"
#include "sh/matrix.hpp"
#include "sh/operators.hpp"
#include "sh/analysis.hpp"
#include "sh/passes.hpp"
#include "sh/print.hpp"
#include "sh/program.hpp"
#include "sh/table.hpp"
#include "sh/waves.hpp"
