"""Case files read as yaml-cpp and editors' YAML plugins read them (YAML 1.2 numbers): Debian's
PyYAML follows YAML 1.1 and takes `1.0e8` for a string."""
import re

import yaml


class Loader(yaml.SafeLoader):
    pass


Loader.add_implicit_resolver("tag:yaml.org,2002:float", re.compile(
    r"^[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?$|^[-+]?\.(inf|Inf|INF)$|^\.(nan|NaN|NAN)$"),
    list("-+0123456789."))


def load(path):
    with open(path) as f:
        return yaml.load(f, Loader=Loader)
