"""placeholder"""


def critical_stiffness(*a, **k):
    raise NotImplementedError


def interface_response(*a, **k):
    raise NotImplementedError
