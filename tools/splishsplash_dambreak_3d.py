#!/usr/bin/env python3
"""Headless SPlisHSPlasH (pysplishsplash 2.19.0) run of isph's 3D dam break, for
tools/peers_dambreak_3d.sh.

Adapted from ../shared/peers/splishsplash_driver.py (the project's working headless driver):
same settings (Akinci boundary particles, CFL with a 5 ms cap, the solver's default tolerance,
2..100 iterations), but the geometry of isph's scenes/dam_break_3d.toml instead of
SPlisHSPlasH's own dam break. isph's z (up) is SPlisHSPlasH's y:

  tank   isph [0, 1.0] x [0, 0.4] x [0, 0.6]  ->  box x [0, 1.0], y [0, 0.6], z [0, 0.4]
  block  isph [0, 0.3] x [0, 0.4] x [0, 0.5]  ->  x [0, 0.3], y [0, 0.5], z [0, 0.4]

SPlisHSPlasH's particle spacing is twice its radius. Its fluid keeps one spacing from the walls
(isph: half a spacing; see `block_end`), so the block loses one layer across the tank's width:
15 x 25 x 19 = 7,125 particles at dx = 0.02 m against isph's 15 x 20 x 25 = 7,500.

Only the time-stepping loop is timed, from the end of step 1 to the end of the last step (step
1 includes the boundary initialisation), as in the shared driver. At the end the density of
every fluid particle (SPlisHSPlasH's, summed at the start of the last step, boundary included)
gives the mean compression mean(max(rho/rho0 - 1, 0)): the quantity the pressure solver drives
below its tolerance (on its predicted density), and one that the density deficit of the
truncated kernel at the free surface does not enter.

The last line is machine-readable: `peer=splishsplash key=value ...`.
"""
import argparse
import json
import os
import sys
import time

p = argparse.ArgumentParser()
p.add_argument("--spacing", type=float, default=0.02, help="particle spacing dx [m] (radius dx/2)")
p.add_argument("--solver", default="DFSPH", choices=["IISPH", "DFSPH"])
p.add_argument("--stop", type=float, default=0.3, help="simulated time to run [s]")
p.add_argument("--tank", default="1.0,0.4,0.6", help="tank x,y,z in isph's axes (z up) [m]")
p.add_argument("--block", default="0.3,0.4,0.5", help="water block x,y,z in isph's axes [m]")
p.add_argument("--viscosity", type=float, default=1.0e-6,
               help="kinematic viscosity [m^2/s] (isph's water; 'Standard' viscosity method)")
p.add_argument("--maxerror", type=float, default=None,
               help="density error tolerance in percent (default: the solver's, 0.01)")
p.add_argument("--maxdt", type=float, default=0.005, help="largest time step (CFL cap) [s]")
p.add_argument("--workdir", default="/tmp/splash_dambreak_3d")
a = p.parse_args()

import numpy as np
import pysplishsplash as sph


def isph_to_splash(v):
    """(x, y, z) with z up -> SPlisHSPlasH's (x, y, z) with y up."""
    return [v[0], v[2], v[1]]


tank = isph_to_splash([float(x) for x in a.tank.split(",")])
block = isph_to_splash([float(x) for x in a.block.split(",")])
r = 0.5 * a.spacing
# The regular block sampling puts particles at start + 2r (k + 1) up to end - 2r. The first
# particle is one spacing from the wall, not half a spacing as in isph: with isph's placement the
# first step compresses the fluid at the walls to 1.66 rho0 and it explodes (measured, Akinci
# and volume-map boundaries alike). A free face (x = 0.3, top) keeps isph's position; a face on
# a wall (the tank's far side: the block spans its width) loses a layer.
block_end = [b + 2 * r if b < t else t for b, t in zip(block, tank)]
os.makedirs(a.workdir, exist_ok=True)

box_obj = os.path.join(os.path.dirname(sys.executable), "data", "models", "UnitBox.obj")
if not os.path.exists(box_obj):  # a self-written unit cube, as in the shared driver
    box_obj = os.path.join(a.workdir, "UnitBox.obj")
    v = [(-.5, -.5, .5), (.5, -.5, .5), (-.5, .5, .5), (.5, .5, .5),
         (-.5, .5, -.5), (.5, .5, -.5), (-.5, -.5, -.5), (.5, -.5, -.5)]
    f = [(1, 2, 3), (3, 2, 4), (3, 4, 5), (5, 4, 6), (5, 6, 7), (7, 6, 8),
         (7, 8, 1), (1, 8, 2), (2, 8, 4), (4, 8, 6), (7, 1, 5), (5, 1, 3)]
    with open(box_obj, "w") as fh:
        fh.write("".join("v %g %g %g\n" % t for t in v) + "".join("f %d %d %d\n" % t for t in f))

solver_block = {"minIterations": 2, "maxIterations": 100}
if a.maxerror is not None:
    solver_block["maxError"] = a.maxerror
if a.solver == "DFSPH":
    solver_block.update({"maxIterationsV": 100, "maxErrorV": 0.1, "enableDivergenceSolver": True})
cfg = {
    "particleRadius": r,
    "simulationMethod": {"IISPH": 3, "DFSPH": 4}[a.solver],
    "gravitation": [0, -9.81, 0],
    "timeStepSize": min(0.001, a.maxdt),
    "cflMethod": 1,  # standard CFL on the largest particle speed
    "cflFactor": 1,
    "cflMaxTimeStepSize": a.maxdt,
    "boundaryHandlingMethod": 0,  # Akinci 2012 boundary particles
    "enablePartioExport": False,
    "enableVTKExport": False,
    a.solver: solver_block,
}
scene = {
    "Configuration": cfg,
    "Materials": [{"id": "Fluid", "density0": 1000, "viscosityMethod": 1,
                   "Standard viscosity": {"viscosity": a.viscosity}}],
    "RigidBodies": [{
        "geometryFile": box_obj, "translation": [0.5 * t for t in tank],
        "rotationAxis": [1, 0, 0], "rotationAngle": 0, "scale": tank,
        "isDynamic": False, "isWall": True, "mapInvert": True, "mapThickness": 0.0,
        "mapResolution": [20, 20, 20]}],
    "FluidBlocks": [{"denseMode": 0, "start": [0, 0, 0], "end": block_end,
                     "translation": [0, 0, 0], "scale": [1, 1, 1]}],
}
scene_path = os.path.join(a.workdir, "dam_break_3d_%s_dx%g.json" % (a.solver, a.spacing))
with open(scene_path, "w") as fh:
    json.dump(scene, fh, indent=1)

base = sph.Exec.SimulatorBase()
base.init(["splash", "--no-gui", "--no-cache", "--stopAt", str(a.stop),
           "--output-dir", os.path.join(a.workdir, "out"), scene_path], "peers")
stamps, dts, iterations = [], [], []


def after_step():
    stamps.append(time.perf_counter())
    dts.append(sph.TimeManager.getCurrent().getTimeStepSize())
    iterations.append(sph.Simulation.getCurrent().getTimeStep().getNumIterations())


base.setTimeStepCB(after_step)
base.initSimulation()
base.runSimulation()

sim = sph.Simulation.getCurrent()
fluid = sim.getFluidModel(0)
n = fluid.numActiveParticles()
rho0 = fluid.getDensity0()
ratio = np.array([fluid.getDensity(i) for i in range(n)]) / rho0 - 1.0
wall = stamps[-1] - stamps[0]
sim_time = sph.TimeManager.getCurrent().getTime() - dts[0]
timed = len(stamps) - 1
fields = {
    "solver": a.solver,
    "spacing": a.spacing,
    "fluid": n,
    "boundary": sim.getBoundaryModel(0).numberOfParticles(),
    "steps": timed,
    "sim_time": "%.4f" % sim_time,
    "wall": "%.3f" % wall,
    "wall_per_sim_second": "%.2f" % (wall / sim_time),
    "us_per_fluid_particle_step": "%.3f" % (wall / timed / n * 1e6),
    "dt_mean": "%.3e" % (sum(dts) / len(dts)),
    "iterations_mean": "%.2f" % (sum(iterations) / len(iterations)),
    "max_error_percent": "%g" % sim.getTimeStep().getValueFloat(type(sim.getTimeStep()).MAX_ERROR),
    "compression_mean": "%.3e" % np.maximum(ratio, 0.0).mean(),
}
print("peer=splishsplash " + " ".join("%s=%s" % kv for kv in fields.items()))
sys.stdout.flush()
# The bindings' teardown can crash after a headless run; the results are out.
os._exit(0)
