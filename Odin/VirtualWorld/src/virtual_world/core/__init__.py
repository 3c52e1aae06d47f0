"""The VirtualWorld Core (thesis chapter 5): ROS-free rigid-body simulation over ODE.

Layers, each a module of its own:
  validation  checks of arguments (nothing reaches ODE unchecked: ODE ends the process on bad
              input, so an error raised by the Core means nothing changed);
  shapes      shapes from Object/Part parameters, collision meshes;
  mass        mass properties of shapes (ODE's formulas, trimesh for meshes) and their checks;
  records     what the Core keeps of what it built, and the results it answers;
  scene       one ODE world and the records that name what is in it;
  objects, joints, motors, actuation, forces, snapshots, propagation, readout
              the requests, by topic, over a scene (actuation: Set Velocity and Set Servo;
              propagation: body state vectors and propagations);
  world       ``Core``: one scene behind a lock, the world parameters and the step;
  loop, step_values
              the node's running loop and step values, without ROS.
Below them, ``virtual_world.ode`` holds everything that calls ODE (handles, bodies, joints, the
C world of odin_step.c).

Conventions: SI units; world frame unless said; quaternions (w, x, y, z) as ODE orders them.
"""
from odin_common.interface import (AxisFrame, ForceKind, JointParameter, JointType, MotorKind,
                                   Solver)
from odin_common.specs import (CompositeSpec, EntitySpec, JointSpec, MotorSpec, ObjectSpec,
                               PartSpec)
from odin_common.world_parameters import WorldParameters
from virtual_world.core.records import (Built, BuiltEntity, BuiltGeometry, Collision,
                                        JointState, Removed)
from virtual_world.core.world import Core

# the interface's constants under their short names (Messages/Joint, JointParameter, ...)
BALL, HINGE, SLIDER, PISTON, UNIVERSAL, HINGE2, PR, PU, FIXED, PLANE2D = JointType
(LO_STOP, HI_STOP, BOUNCE, CFM, ERP, STOP_ERP, STOP_CFM, SUSPENSION_ERP, SUSPENSION_CFM,
 FUDGE_FACTOR, VELOCITY, MAX_FORCE) = JointParameter
ANGULAR, LINEAR = MotorKind
FORCE, TORQUE = ForceKind
QUICKSTEP, WORLDSTEP, AUTO_SOLVER = Solver

__all__ = ["Core", "ObjectSpec", "PartSpec", "CompositeSpec", "EntitySpec", "JointSpec",
           "MotorSpec", "Built", "BuiltEntity", "BuiltGeometry", "Removed", "JointState",
           "Collision", "WorldParameters", "JointType", "JointParameter", "MotorKind",
           "AxisFrame", "ForceKind", "Solver",
           "BALL", "HINGE", "SLIDER", "PISTON", "UNIVERSAL", "HINGE2", "PR", "PU", "FIXED",
           "PLANE2D", "LO_STOP", "HI_STOP", "BOUNCE", "CFM", "ERP", "STOP_ERP", "STOP_CFM",
           "SUSPENSION_ERP", "SUSPENSION_CFM", "FUDGE_FACTOR", "VELOCITY", "MAX_FORCE",
           "ANGULAR", "LINEAR", "FORCE", "TORQUE", "QUICKSTEP", "WORLDSTEP",
           "AUTO_SOLVER"]
