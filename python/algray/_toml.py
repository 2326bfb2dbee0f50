"""Python values as TOML text, for Scene.set and Scene.from_dict, and TOML text back (tomllib)."""
import json
import math
import tomllib


def value(v):
    """One value: numbers and booleans as TOML writes them, strings quoted, lists and dicts inline."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v) or math.isinf(v):
            return ("-" if v < 0 else "") + ("nan" if math.isnan(v) else "inf")
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{key(k)} = {value(x)}" for k, x in v.items()) + " }"
    if hasattr(v, "tolist"):  # numpy arrays and scalars
        return value(v.tolist())
    return "[" + ", ".join(value(x) for x in v) + "]"


def key(k):
    return k if k.replace("_", "").replace("-", "").isalnum() else json.dumps(k)


def document(data):
    """A whole scene: top-level tables, and lists of tables (light = [{...}, {...}]) as [[light]]."""
    lines = []
    for name, table in data.items():
        if isinstance(table, dict):
            lines.append(f"[{key(name)}]")
            lines += [f"{key(k)} = {value(v)}" for k, v in table.items()]
        elif isinstance(table, (list, tuple)) and table and all(isinstance(t, dict) for t in table):
            for t in table:
                lines.append(f"[[{key(name)}]]")
                lines += [f"{key(k)} = {value(v)}" for k, v in t.items()]
        else:
            raise ValueError(f"scene key {name!r}: expected a table (dict) or a list of tables")
    return "\n".join(lines) + "\n"


def loads(text):
    return tomllib.loads(text)
