"""Test-suite configuration: pytester for testing the otonav pytest plugin itself."""

pytest_plugins = ["pytester"]
