-- params.lua: run with --set a=3 --set b=hello --set c=true [--set d=...].
local a, b, c = outcrop.param("a"), outcrop.param("b"), outcrop.param("c")
assert(a == 3 and math.type(a) == "integer", "a should be the integer 3")
assert(b == "hello", "b should be the string 'hello'")
assert(c == true, "c should be the boolean true")
assert(outcrop.param("absent") == nil, "an absent parameter is nil")
print("params", a, b, c)
print("d", outcrop.param("d"))
