"""Testing tools for otonav users: a pytest plugin (registered as the ``otonav`` pytest
entry point) that runs ``@pytest.mark.sim`` tests on a virtual-time loop."""
