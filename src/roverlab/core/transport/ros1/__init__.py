"""ROS 1 on the wire: TCPROS, the XML-RPC master and slave APIs, and the master itself.

Layers, each a small module: :mod:`.header` (connection header codec), :mod:`.framing`
(bounded length-prefixed units), :mod:`.xmlrpc` (stdlib XML-RPC with timeouts and caps),
:mod:`.names` and :mod:`.params` (graph names, the parameter tree), :mod:`.master`
(``roverlab roscore``), :mod:`.slave` (a node's XML-RPC API), :mod:`.tcpros` (links),
:mod:`.peer` (a process's nodes as ROS 1 participants, on raw bytes).
"""
