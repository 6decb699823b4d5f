"""The ROS-like runtime: clock, scheduler, graph, names, parameters and the node base."""

from fleetsim.runtime.graph import Graph, Publisher, ServiceClient, Subscription
from fleetsim.runtime.node import Node
from fleetsim.runtime.params import ParamTree, describe_params, load_params, param
from fleetsim.runtime.runtime import Runtime
from fleetsim.runtime.scheduler import Timer

__all__ = [
    "Graph",
    "Node",
    "ParamTree",
    "Publisher",
    "Runtime",
    "ServiceClient",
    "Subscription",
    "Timer",
    "describe_params",
    "load_params",
    "param",
]
