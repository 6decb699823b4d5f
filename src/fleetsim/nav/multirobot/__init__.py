"""Multi-robot navigation: position sharing, ORCA, collision avoidance (collvoid)."""
