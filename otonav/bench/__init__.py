"""``otonav bench``: the stack against bare physics, measured in one session."""
