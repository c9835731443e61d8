"""The plane-strain engine's quadrilaterals and node update: the one-point quadrilateral with
hourglass control (:mod:`.element`), the fully integrated B-bar quadrilateral (:mod:`.bbar`),
the node update with tool contact and node-splitting separation (:mod:`.node_contact`) and the
tool's kinematics and support (:mod:`.tool_motion`)."""
