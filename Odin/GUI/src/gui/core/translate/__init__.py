"""A loaded Kautham problem -> the build plan that makes it in the VirtualWorld (ROS-free).

``plan_problem(problem, defaults)`` returns a ``gui.core.plan.BuildPlan``; ``BuildDefaults``
holds the choices a caller may change. The general rules (instances, bodies, joints, motors,
attachments, Kautham's physics) are ``planner``'s and ``joints``'; a car's wheels and the
friction of Kautham's car planner ``car``'s; a fixed-base robot's base and the drive of
Kautham's chain planner ``chain``'s; a shape's body ``gui.core.bodies``'.

How a problem maps to the world:
- The world first (``gui.core.world_settings``): one Set World with every world parameter and
  one Set Step with every step value, the problem's own where it has them, else the documented
  defaults (docs/parameters.md, Set Step's 0.001 s x 40 at 25 Hz), never what the world held
  before: loading a problem (load_problem, the window's Open, plan, the experiments) gives the
  same world in a node that ran anything before as in a fresh one. A problem has values of its
  own under Kautham's physics (``Problem.physics``: one of its ODE planners;
  ``BuildDefaults.ground`` asks for it in any problem): what Kautham's ODE environment uses
  (gravity, ERP, CFM, contacts per pair, the step), then an infinite ground plane at z = 0
  (``GROUND``, static).
- A robot with joints -> one Build Entity (one object or composite per link, internal
  collisions off), then per link one Set Joint: revolute -> HINGE, prismatic -> SLIDER (anchor
  and axis from the joint frame where the robot is built, world frame; LO_STOP/HI_STOP from the
  limits, relative to the value the joint is built at), a non-movable link -> FIXED joint to
  its parent; a car's wheels -> HINGE2 with CarEnvironment's suspension (ERP 0.4 / CFM 0.8):
  for a car of Kautham's car planner CarEnvironment's world axes (steering about +z for the
  first two wheels, -z for the others, spin about +y, whatever the car's pose: a positive
  wheel speed rolls it toward world -x) and its contact friction by body kind
  (``environment.CAR_FRICTION``, the ground's too); for any other car axes from its own frame
  (steering about the base's up, opposite for the wheels ahead of its centre and the others;
  both reversed like a hinge's, so that a positive steering turns left and a positive wheel
  speed rolls the car along its +x). Then one Set Motor per movable joint
  (angular for hinges and hinge-2s, linear for sliders; zero speed; the joint's effort limit
  as its force limit, infinite without one; the chain of
  Kautham's chain planner gets PlanarChainEnvironment's 7 N m and 1 rad/s for every joint
  instead, whatever its URDF says), id "motor:" + joint id; a joint with friction gets a second
  motor at zero speed whose force limit is the friction ("friction:" + joint id), a joint
  with damping a third at zero speed, unlimited force and CFM 1 / damping, which makes ODE
  apply exactly -damping x the joint's rate ("damping:" + joint id); under Kautham's own
  physics (one of its ODE planners) no joint has either, as in its ODE environment. Last, a
  robot (not a car, whose wheels' motors at zero speed hold it) gets one Set Servo that holds
  every joint at the value it is built at (``gui.core.plan.HoldStep``): motors at zero speed
  alone let an arm creep (3.3 mm in 10 s for the KUKA LWR), servos hold it within 0.1 mm; a
  Set Velocity of a motor takes it out of servo mode, a Set Position of the robot moves the
  servos' targets with it.
- The base by the robot's kind (``gui.core.model``): FIXED_BASE -> in a current problem under
  Kautham's physics a dynamic body held by a FIXED joint to the world (Kautham's chain),
  anywhere else (a 2012 problem, a geometric planner's) a fixed (kinematic) body that never
  moves, whatever overlaps it (the YuMi's arm bases lie inside its torso); FREE_BODY,
  MOBILE, CAR -> under Kautham's physics a dynamic
  body, free; FREE_BODY and MOBILE otherwise (a geometric planner's problem, where Kautham
  simulates nothing and only the controls place the base) a fixed (kinematic) body held at
  the pose it is built at, as a fixed-base robot's joints are held: gravity and contacts never
  move it, a Set Velocity or Set Position does (``run_path --tracked`` drives it so).
- A robot is built at its start (the query's ``<Init>``), at Home when the problem has no query
  (``BuildDefaults.start_at_query``): where Kautham leaves a problem it loads, in both formats
  (2012's ``Problem::createCSpaceFromFile`` collision-checks ``<Init>`` by moving the robots
  there; a 2012 Home may put an arm inside its scene, e.g. the TX90's elbow 4.5 mm into
  teleoperation_test.iv). ``RobotHandle.built_at`` keeps the joint values the world's joint
  readings are relative to.
- A robot made of one link (a bare shape or a one-link URDF) is a free-flying body: an entity
  of one object, no joint.
- A static obstacle -> Build Object/Composite with ``geometry_only``. A movable obstacle (a .rob
  scene, a URDF with masses, ``<Scene movable="true">``, any obstacle under Kautham's physics,
  an attached obstacle) -> bodies with masses; a multi-link one is built like a robot but its
  base is left free (without Kautham's physics, held kinematic where it is put, like a mobile
  robot's). In a current problem without Kautham's physics a one-link obstacle body not
  attached at the start is held where the problem puts it by a FIXED joint to the world
  (key "name/<hold>", ``BuildPlan.holds``): only an attachment moves an obstacle there; a
  tracked path's Transfer lets it go when it attaches it and holds it again where it leaves
  it. ``<InitialAttachedObstacle>`` -> a FIXED joint between the link and the obstacle's
  (base) body, as they are placed.
- Shapes: a mesh -> mesh object (vertices in the link frame); one primitive -> primitive
  object whose body sits at the primitive's pose in the link; anything else -> a composite
  whose frame is the link frame (one part per primitive, one for the mesh), id ">p1>p2...".
- Masses: the file's mass; a URDF robot's link without ``<inertial>`` (massless to URDF and to
  Kautham, which no body can be) its shape's volume at ``BuildDefaults.massless_density``
  (water's, at least ``LIGHTEST_LINK``: 1 kg fingertips sagged the Allegro hands' 1 N m
  joints); else ``BuildDefaults.link_mass`` (1 kg, what Kautham's ODE environment gives an
  obstacle without a mass; a .rob ``<Weight>`` is a planner weight, not a mass); a
  composite's mass is shared among its parts in proportion to their
  volumes. Inertia (``gui.core.inertia``): the URDF's tensor about its centre of mass where it
  is a rigid body's and plausible for the link's shape, the shape's at uniform density
  otherwise. The world refuses a given inertia far too light in rotation for the body's
  geometry (a principal radius of gyration under ``odin_common.limits.MIN_GYRATION_FRACTION``
  of the geometry's reach from that axis: ODE's solver would abort the process) or far too
  heavy (over ``MAX_GYRATION_MULTIPLE`` times that reach, or over ``MAX_INERTIA``), so such a
  tensor is set aside for the shape's too. Contact surfaces: the link's (URDF contact
  coefficients) on its object or parts.
- Names (thesis 8.3): links are "robot/link" (Kautham's own .cntr naming), one-link instances
  keep the instance name; instance names come from the robot's name or the obstacle's file
  name, numbered "_2", "_3"... on collision; composite parts are "name#k".
- All or nothing (``gui.planning.rehearsal.load_scene``): load_problem and the window's Open
  build the whole plan first in a Core of their own process, started as the world is (its
  parameters, step values and its node's ``~max_objects``, ``~max_mesh_triangles``,
  ``~max_snapshots``, ``~max_request_mb``), and send it only when every request was taken
  there; otherwise one line names the step and the world is unchanged. A step the world still
  refuses (another client in between, a clash with what ``--keep`` keeps) is undone: what the
  load built is removed, the parameters and step values it set are put back, and a running
  world is started again. A plan a Core took is not rehearsed again for a world that starts
  the same (``gui.planning.rehearsal_cache``: a digest of the plan's values, the world and
  the Core's code, kept beside the shape cache; ``--no-cache`` turns it off).
"""
from gui.core.translate.planner import GROUND, BuildDefaults, plan_problem

__all__ = ["GROUND", "BuildDefaults", "plan_problem"]
