"""Posture planning: a pose-dependent elastic multibody model of the robot (calibrated at the
measured posture), the postures that reach a bore, their stiffness, modes and critical depth,
and the recommended one. User guide: docs/plan.md; command: ``robobore plan posture``."""
