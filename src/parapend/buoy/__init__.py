"""The pendulum inside a floating buoy, coupled both ways (see the submodules)."""
