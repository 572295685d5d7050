"""A small tree whose ticks change statuses at several depths and over several ticks (the Delay runs)."""

SMALL_TREE_XML = (
    '<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence>'
    "<Fallback><AlwaysFailure/><AlwaysSuccess/></Fallback>"
    '<Inverter><AlwaysFailure/></Inverter><Delay delay_msec="1"><AlwaysSuccess/></Delay>'
    "</Sequence></BehaviorTree></root>"
)
