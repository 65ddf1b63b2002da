// ChainTube — umbrella header of the core library.
#pragma once

#include "chaintube/cut.h"
#include "chaintube/hose.h"
#include "chaintube/material.h"
#include "chaintube/metrics.h"
#include "chaintube/profile.h"
#include "chaintube/reel.h"
#include "chaintube/resolution.h"
#include "chaintube/route.h"
#include "chaintube/scene.h"
#include "chaintube/surface.h"
#include "chaintube/tension.h"
#include "chaintube/types.h"
