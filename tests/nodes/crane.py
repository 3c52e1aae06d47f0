"""A crane of our own for node tests: a 1 m mast and a 1 m boom slewing +-3 rad about z at
0.6 m up the mast (the URDF), each test writing the problem it needs around it."""

CRANE_URDF = """<?xml version="1.0"?><robot name="crane">
 <link name="mast"><collision><geometry><box size="0.2 0.2 1"/></geometry></collision></link>
 <link name="boom"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.05 0.05"/>
  </geometry></collision></link>
 <joint name="slew" type="revolute"><parent link="mast"/><child link="boom"/><origin
  xyz="0 0 0.6"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="30" velocity="1"/>
 </joint>
</robot>"""
