"""Sane ranges for what requests may ask: a value outside them is refused (naming the field and
the limit) before it can reach ODE, where it would make a step diverge or exhaust memory. Where
a range depends on the world, it is a world parameter (world_parameters: divergence_speed,
divergence_angular_speed, world_extent: velocities and positions are checked against those)."""

MAX_FORCE = 1e7
"""N (forces) or N m (torques): a persistent body or joint force, a motor's maximum force."""

MIN_MASS = 1e-9
"""kg: the lightest body."""
MAX_MASS = 1e9
"""kg: the heaviest body."""

MIN_SIZE = 1e-6
"""m: the smallest dimension of a primitive (the largest is twice the world's extent)."""

MAX_MOTOR_SPEED = 1e5
"""rad/s or m/s: a motor's goal speed."""

MIN_STEP = 1e-7
"""s: the shortest step."""

MAX_GRAVITY = 1e4
"""m/s^2: each component of gravity."""

MAX_MESH_TRIANGLES = 2_000_000
"""Triangles of one mesh (the world node's ~max_mesh_triangles may lower it)."""
