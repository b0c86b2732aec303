-- closedout.lua: prints while a file it writes is open, flushing standard
-- output; when the interpreter starts with standard output closed, the
-- print must not land in the file.
local f = assert(io.open("out.txt", "w"))
f:write("written\n")
print("printed")
io.stdout:flush()
f:close()
